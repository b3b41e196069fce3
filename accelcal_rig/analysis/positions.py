"""How many positions a calibration needs (paper §4.2, Fig. 8, Table 4).

From a campaign of many orientations at one temperature (`procedures/positions-study.yaml`: 1296 spread
evenly over the sphere), the error model is fitted again on subsets of the paper's sizes — several random
subsets and one structured subset (the poses nearest an even spread of that many directions) each — and
every fit is scored by the RMSE of |g| on the poses it did not use. A subset whose fit the design cannot
support (too few directions for the parameters) is counted as failed, not dropped silently.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from accelcal_rig.fit.lm import DegenerateDesign, FitMode, FreeParameters, fit_sfem
from accelcal_rig.fit.metrics import noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.sfem import correct
from accelcal_rig.plan.schedules import sphere
from accelcal_rig.store.read import VectorPoses

#: The numbers of positions of the paper's Table 4.
PAPER_SIZES = (1296, 648, 324, 162, 81, 64, 48, 36, 24, 21, 18, 16, 12)


@dataclass(frozen=True)
class SubsetScore:
    size: int
    kind: str                    # "random" or "structured"
    rmse_after_mg: float         # on the held-out poses (on all of them when the subset is every pose)
    rmse_before_mg: float        # the same poses uncalibrated
    held_out: int


@dataclass(frozen=True)
class SizeSummary:
    serial: str
    size: int
    structured_mg: float
    random_median_mg: float
    random_max_mg: float
    before_mg: float
    failed: int                  # random subsets the fit refused
    held_out: int


def structured_subset(directions: np.ndarray, size: int) -> np.ndarray:
    """Indices of the poses nearest `size` evenly spread directions, each pose used once."""
    targets = sphere(size)
    chosen: list[int] = []
    similarity = targets @ directions.T
    for row in similarity:
        row = row.copy()
        row[chosen] = -np.inf
        chosen.append(int(np.argmax(row)))
    return np.array(sorted(chosen))


def score_subsets(poses: VectorPoses, sizes: tuple[int, ...], mode: FitMode, free: FreeParameters, subsets: int,
                  rng: np.random.Generator) -> list[SubsetScore]:
    n = len(poses.mean)
    directions = poses.mean / np.linalg.norm(poses.mean, axis=1, keepdims=True)
    accuracy_rad = np.radians(poses.reference_accuracy_arcsec / 3600.0)
    scores = []
    for size in (s for s in sizes if s <= n):
        choices = [("structured", structured_subset(directions, size))]
        choices += [("random", np.sort(rng.choice(n, size, replace=False))) for _ in range(subsets if size < n else 0)]
        for kind, chosen in choices:
            held = np.setdiff1d(np.arange(n), chosen) if size < n else np.arange(n)
            try:
                fit = fit_sfem(poses.mean[chosen], poses.stderr[chosen],
                               poses.reference[chosen] if mode == "reference" else None, mode, free, accuracy_rad)
            except DegenerateDesign:
                scores.append(SubsetScore(size, kind, float("nan"), norm_rmse_mg(poses.mean[held]), len(held)))
                continue
            compensated = correct(poses.mean[held], fit.parameters)
            scores.append(SubsetScore(size, kind, norm_rmse_mg(compensated), norm_rmse_mg(poses.mean[held]),
                                      len(held) if size < n else 0))
    return scores


def summarise(serial: str, scores: list[SubsetScore]) -> list[SizeSummary]:
    rows = []
    for size in sorted({s.size for s in scores}, reverse=True):
        structured = next(s for s in scores if s.size == size and s.kind == "structured")
        random = np.array([s.rmse_after_mg for s in scores if s.size == size and s.kind == "random"])
        ok = random[np.isfinite(random)]
        rows.append(SizeSummary(serial, size, structured.rmse_after_mg,
                                float(np.median(ok)) if len(ok) else float("nan"),
                                float(np.max(ok)) if len(ok) else float("nan"),
                                structured.rmse_before_mg, int(np.sum(~np.isfinite(random))), structured.held_out))
    return rows


def floor_mg(poses: VectorPoses) -> float:
    """The RMSE the per-pose standard errors alone leave: what a perfect calibration would score."""
    return noise_floor_mg(poses.mean, poses.stderr)
