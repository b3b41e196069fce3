"""Figures of `rig analyze`: positions (paper Fig. 8), tilt, free cool-down (paper Fig. 11)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.analysis.positions import SizeSummary
from accelcal_rig.report.figures import pyplot, save


def positions_figure(rows: list[SizeSummary], floors_mg: dict[str, float], mode: str, path: Path) -> Path:
    """RMSE of |g| on held-out poses against the number of positions: before calibration on the left
    axis, after on the right (log), the median and worst of the random subsets and the structured one."""
    plt = pyplot()
    figure, left = plt.subplots(figsize=(9, 5.5), constrained_layout=True)
    right = left.twinx()
    colours = plt.get_cmap("tab10")
    for index, serial in enumerate(dict.fromkeys(r.serial for r in rows)):
        mine = sorted((r for r in rows if r.serial == serial), key=lambda r: r.size)
        sizes = np.array([r.size for r in mine])
        colour = colours(index % 10)
        left.plot(sizes, [r.before_mg for r in mine], ":", color=colour, lw=1)
        right.plot(sizes, [r.random_median_mg for r in mine], "o-", ms=3, color=colour, label=f"{serial} random (median)")
        right.fill_between(sizes, [r.random_median_mg for r in mine], [r.random_max_mg for r in mine], color=colour,
                           alpha=0.12, lw=0)
        right.plot(sizes, [r.structured_mg for r in mine], "s--", ms=3, color=colour, lw=0.8,
                   label=f"{serial} evenly spread")
        right.axhline(floors_mg[serial], color=colour, lw=0.6, ls="-.")
    left.set_xscale("log")
    right.set_yscale("log")
    left.set_xlabel("number of positions in the fit")
    left.set_ylabel("RMSE of |g| before calibration (mg, dotted)")
    right.set_ylabel("RMSE of |g| after calibration, on the poses left out (mg)")
    ticks = sorted({r.size for r in rows})
    left.set_xticks(ticks)
    left.set_xticklabels([str(t) for t in ticks], fontsize=7, rotation=45)
    right.legend(fontsize=7, loc="upper right")
    figure.suptitle(f"How many positions a calibration needs ({mode} fit; shaded: median to worst of the random "
                    "subsets; dash-dot: noise floor) — paper Fig. 8")
    return save(figure, path)
