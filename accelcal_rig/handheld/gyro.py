"""A hand-held gyroscope calibration: bias from the still intervals, scale and misalignment from the turns
between them, seen through the accelerometer's gravity directions.

Model: raw_dps = K·ω + bias + G·f, ω the true rate in the accelerometer's calibrated frame (°/s), K (3×3) the
scale factors on its diagonal and the cross-axis terms off it (K_xy: raw x per true y), f the specific force
the compensated accelerometer reads (g) and G the g-sensitivity (°/s per g). While still the gyro reads its
bias and G·f (and Earth's rate, 0.0042 °/s, which is not taken out: it needs the site's latitude and each pose's
heading). G is fitted only where the still intervals ask for it: their means against bias alone and against
bias + G (linear, weighted by their standard errors), G kept when an F-test on the drop in χ² says a gyro
without one would show it less than once in a hundred recordings, and when the intervals' forces span space.
Between two consecutive static intervals the corrected rate K⁻¹·(raw − bias − G·f) is integrated into a
rotation at the recording's own sample times; the first interval's gravity direction turned by it should be
the next interval's. `scipy.optimize.least_squares` fits bias, K (and G) to those direction residuals and to
the still intervals' means.

Gauge: a turn about gravity leaves the gravity direction where it was, so each move says nothing about its
rotation about the next interval's gravity (two equations per move, not three), and a recording whose turns
are all about the vertical, or full turns (360° about any axis is no rotation at all), determines neither
the scale of the axis turned about nor the terms that would tilt it. What the moves determined is read off
the Jacobian (rank, conditioning, each parameter's 1σ). Where the moves cannot say (none turns the sensor,
gravity turns where the gyro does not, or any K term is left undetermined) K is not fitted: the gyroscope is
calibrated for what the still intervals determine, its bias (and G), K held at the nominal sensitivity and said
to be, with the reason; never a K the data never saw.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from scipy.stats import f as f_distribution

from accelcal_rig.handheld.recording import Recording, RecordingUnusable
from accelcal_rig.handheld.static_intervals import StaticInterval

#: Earth's rotation rate, °/s: what a perfect gyro at rest reads (its projection on each axis depends on the
#: latitude and the heading, neither of which a hand-held recording knows).
EARTH_RATE_DPS = math.degrees(7.2921150e-5)
#: A move the gyro measures as less than this turn is no rotation (the sensor was put down again as it was).
MIN_TURN_DEG = 10.0
#: A K term whose 1σ exceeds this is not determined: hand-held moves should pin scale and cross-axis terms,
#: which are ~1 % and ~0.5 % on a MEMS gyro, to a fraction of that.
MAX_SIGMA_MATRIX = 5e-3
#: Gravity cannot turn further than the sensor does: a move where it turns more than this × the gyro's turn
#: (plus TURN_SLACK_DEG) is a splice in the recording, another sensor's gyro, or gyro units off.
TURN_RATIO = 1.2
TURN_SLACK_DEG = 5.0
AXES = "xyz"
PARAMETER_NAMES = [f"bias_{a}" for a in AXES] + [f"K_{r}{c}" for r in AXES for c in AXES]
GSENS_NAMES = [f"G_{r}{c}" for r in AXES for c in AXES]
#: The g-sensitivity is fitted when a gyro without one would drop the still intervals' χ² this much less often.
GSENS_ALPHA = 0.01
#: The intervals' forces about their mean must spread this far (g, the smallest singular value) in every
#: direction for G to be told apart from the bias: the six faces reach √2 g.
MIN_FORCE_SPREAD_G = 0.3


@dataclass(frozen=True)
class HandheldGyroFit:
    """The gyroscope's bias, K and G (raw_dps = K·ω + bias + G·f, ω in the accelerometer's calibrated frame), their
    1σ from the least-squares covariance, and how well the moves between still intervals close. K is the identity
    with NaN 1σ when the moves could not determine it (`k_determined` False, the reason in `notes`); G is zero with
    NaN 1σ when the still intervals did not ask for it (`gsens_fitted` False)."""

    bias_dps: np.ndarray              # (3,)
    matrix: np.ndarray                # (3, 3) K: scale factors on the diagonal, cross-axis terms off it
    bias_sigma_dps: np.ndarray        # (3,) 1σ
    matrix_sigma: np.ndarray          # (3, 3) 1σ
    residual_before_deg: np.ndarray   # (segments,) gravity direction misclosure with K = I, bias from the still
    residual_after_deg: np.ndarray    # (segments,) with the fitted bias and K
    segments: int                     # moves between consecutive static intervals used
    turn_deg: np.ndarray              # (segments,) each move's turn, as the calibrated gyro measures it
    noise_dps: np.ndarray             # (3,) per-sample standard deviation while still
    rank: int                         # of the weighted Jacobian, out of 12
    condition: float                  # of the weighted Jacobian with its columns scaled to unit length
    chi2_reduced: float | None        # None with no degrees of freedom left
    notes: list[str] = field(default_factory=list)
    gsens_dps_per_g: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))   # (3, 3) G
    gsens_sigma: np.ndarray = field(default_factory=lambda: np.full((3, 3), np.nan))  # (3, 3) 1σ
    gsens_fitted: bool = False
    gsens_p_value: float | None = None  # of the still intervals' F-test (None: G not determinable from them)
    k_determined: bool = True

    @property
    def scale(self) -> np.ndarray:
        """K's diagonal: raw °/s per true °/s on each axis."""
        return np.diag(self.matrix).copy()

    def correct(self, raw_dps: np.ndarray, force_g: np.ndarray | None = None) -> np.ndarray:
        """Raw readings (…, 3) in °/s, and the specific force (…, 3, g) they were read at → calibrated rates in the
        accelerometer's frame: K⁻¹·(raw − bias − G·f)."""
        raw = np.asarray(raw_dps, dtype=float) - self.bias_dps
        if force_g is not None:
            raw = raw - np.asarray(force_g, dtype=float) @ self.gsens_dps_per_g.T
        return raw @ np.linalg.inv(self.matrix).T

    def report(self) -> dict[str, Any]:
        """What `rig fit-recording` prints (and its --json holds) as `gyro`."""
        return {
            "bias_dps": self.bias_dps, "bias_sigma_dps": self.bias_sigma_dps,
            "scale": self.scale, "scale_sigma": np.diag(self.matrix_sigma),
            "matrix": self.matrix, "matrix_sigma": self.matrix_sigma,
            "residual_rms_before_deg": _rms(self.residual_before_deg),
            "residual_rms_after_deg": _rms(self.residual_after_deg),
            "residual_before_deg": self.residual_before_deg, "residual_after_deg": self.residual_after_deg,
            "segments": self.segments, "turn_deg": self.turn_deg, "noise_dps": self.noise_dps,
            "rank": self.rank, "condition": self.condition, "chi2_reduced": self.chi2_reduced,
            "earth_rate_dps": EARTH_RATE_DPS, "notes": self.notes, "k_determined": self.k_determined,
            "gsens_fitted": self.gsens_fitted, "gsens_p_value": self.gsens_p_value,
            "gsens_dps_per_g": self.gsens_dps_per_g, "gsens_sigma": self.gsens_sigma,
        }


#: G = 0: a gyro whose still reading does not depend on the specific force.
_NO_GSENS = np.zeros((3, 3))


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else float("nan")


@dataclass(frozen=True)
class _Moves:
    """The moves between consecutive static intervals, padded to one power-of-two length so that all are
    integrated at once: per increment the mean raw rate of its two samples and its duration (0 in the
    padding, an identity rotation)."""

    rate_dps: np.ndarray       # (S, L, 3)
    force_g: np.ndarray        # (S, L, 3) the specific force over each increment (what G acts on)
    dt_s: np.ndarray           # (S, L)
    start: np.ndarray          # (S,) index of the interval each move leaves
    sigma_rad: np.ndarray      # (S,) 1σ of one component of its direction residual


def _sample_ranges(t_s: np.ndarray, intervals: Sequence[StaticInterval]) -> np.ndarray:
    """[first, stop) sample indices of each interval."""
    starts = np.searchsorted(t_s, [i.start_s for i in intervals], side="left")
    stops = np.searchsorted(t_s, [i.end_s for i in intervals], side="right")
    return np.column_stack([starts, stops])


def _still_statistics(gyro_dps: np.ndarray, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each interval's mean gyro reading and its standard error (white noise), and the pooled per-sample noise."""
    means = np.array([gyro_dps[a:b].mean(axis=0) for a, b in ranges])
    squares = sum(((gyro_dps[a:b] - m) ** 2).sum(axis=0) for (a, b), m in zip(ranges, means))
    counts = ranges[:, 1] - ranges[:, 0]
    noise = np.sqrt(np.asarray(squares) / max(int(counts.sum() - len(counts)), 1))
    # A coarse gyro may read one code throughout: keep the weights finite.
    stderr = np.maximum(noise, 1e-9)[None, :] / np.sqrt(counts)[:, None]
    return means, stderr, noise


def _moves(recording: Recording, force_g: np.ndarray, ranges: np.ndarray, gravity_sigma_rad: np.ndarray,
           noise_dps: np.ndarray, rate_hz: float) -> tuple[_Moves, list[str]]:
    """The samples from the last still sample of each interval to the first of the next; a move with a gap
    in time (lost samples, a campaign file's turntable moves) cannot be integrated and is left out."""
    assert recording.gyro_dps is not None
    t, gyro = recording.t_s, recording.gyro_dps
    kept, notes, pieces = [], [], []
    for k in range(len(ranges) - 1):
        first, last = ranges[k, 1] - 1, ranges[k + 1, 0]
        dt = np.diff(t[first:last + 1])
        if len(dt) == 0:
            continue
        if dt.max() > 2.5 / rate_hz:
            notes.append(f"the move {t[first]:.2f} → {t[last]:.2f} s has a {dt.max():.3g} s gap in time: left out")
            continue
        kept.append(k)
        pieces.append((0.5 * (gyro[first:last] + gyro[first + 1:last + 1]),
                       0.5 * (force_g[first:last] + force_g[first + 1:last + 1]), dt))
    length = 1 << max(int(math.ceil(math.log2(max((len(d) for _, _, d in pieces), default=1)))), 0)
    rate = np.zeros((len(pieces), length, 3))
    force = np.zeros((len(pieces), length, 3))
    dt_s = np.zeros((len(pieces), length))
    for s, (r, f, d) in enumerate(pieces):
        rate[s, :len(d)], force[s, :len(d)], dt_s[s, :len(d)] = r, f, d
    # Each sample enters two increments with half their durations: its weight in the turn angle.
    weights = 0.5 * (dt_s + np.pad(dt_s, ((0, 0), (1, 0)))[:, :-1])
    angle_sigma = np.radians(float(np.mean(noise_dps))) * np.sqrt((weights**2).sum(axis=1))
    start = np.array(kept, dtype=int)
    sigma = np.sqrt(angle_sigma**2 + gravity_sigma_rad[start] ** 2 + gravity_sigma_rad[start + 1] ** 2)
    return _Moves(rate, force, dt_s, start, sigma), notes


def _compose(rotvec_rad: np.ndarray) -> Rotation:
    """Δ0·Δ1·…·Δ(L−1) for each row of (S, L, 3) body-frame increments, L a power of two, by pairwise
    products: log2(L) vectorised steps instead of L sequential ones, and the order (which matters) kept."""
    rows, length = rotvec_rad.shape[:2]
    quat = Rotation.from_rotvec(rotvec_rad.reshape(-1, 3)).as_quat().reshape(rows, length, 4)
    while quat.shape[1] > 1:
        left = Rotation.from_quat(quat[:, 0::2].reshape(-1, 4))
        right = Rotation.from_quat(quat[:, 1::2].reshape(-1, 4))
        quat = (left * right).as_quat().reshape(rows, -1, 4)
    return Rotation.from_quat(quat[:, 0])


def _turns(moves: _Moves, bias_dps: np.ndarray, matrix: np.ndarray, gsens: np.ndarray = _NO_GSENS) -> Rotation:
    """Each move's rotation (attitude at its end relative to its start, body frame) from the corrected rates."""
    corrected = (moves.rate_dps - bias_dps - moves.force_g @ gsens.T) @ np.linalg.inv(matrix).T
    return _compose(np.radians(corrected) * moves.dt_s[..., None])


def _swept_deg(moves: _Moves, bias_dps: np.ndarray) -> np.ndarray:
    """(S,) the angle each move sweeps, ∫|ω|dt, however it ends: a full turn sweeps 360° and turns by none."""
    increments = np.linalg.norm((moves.rate_dps - bias_dps) * moves.dt_s[..., None], axis=-1)
    return np.asarray(increments.sum(axis=1))


def _tangent_bases(direction: np.ndarray) -> np.ndarray:
    """(S, 2, 3): two unit vectors perpendicular to each direction, the plane a direction residual lies in."""
    helper = np.where(np.abs(direction[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(direction, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return np.stack([e1, np.cross(direction, e1)], axis=1)


def _misclosure(moves: _Moves, gravity: np.ndarray, bias_dps: np.ndarray, matrix: np.ndarray,
                gsens: np.ndarray) -> np.ndarray:
    """(S, 3): observed × predicted gravity direction at each move's end (sin of the angle, about the axis
    that would close it), predicted = the start's gravity turned by the move (g_end = Rᵀ·g_start)."""
    predicted = _turns(moves, bias_dps, matrix, gsens).inv().apply(gravity[moves.start])
    return np.cross(gravity[moves.start + 1], predicted)


def _angles_deg(moves: _Moves, gravity: np.ndarray, bias_dps: np.ndarray, matrix: np.ndarray,
               gsens: np.ndarray = _NO_GSENS) -> np.ndarray:
    """(S,) each move's misclosure angle, °."""
    predicted = _turns(moves, bias_dps, matrix, gsens).inv().apply(gravity[moves.start])
    observed = gravity[moves.start + 1]
    cosine = np.einsum("ij,ij->i", observed, predicted)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(observed, predicted), axis=1), cosine))


def _signed_permutations() -> list[np.ndarray]:
    """The 48 axis maps ±x, ±y, ±z in any order: starting points for K, so a gyro mounted or wired other
    than the accelerometer (imucal's frame is flipped against ours) is not a local minimum away."""
    maps = []
    for order in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            matrix = np.zeros((3, 3))
            matrix[range(3), order] = signs
            maps.append(matrix)
    return maps


def _sigmas(jacobian: np.ndarray) -> tuple[np.ndarray, int, float]:
    """1σ of each parameter (inf along directions the data do not reach), the numerical rank and the
    condition number of the column-scaled Jacobian (units of bias and K differ)."""
    _, singular, vt = np.linalg.svd(jacobian, full_matrices=False)
    tolerance = singular.max() * max(jacobian.shape) * np.finfo(float).eps
    rank = int(np.sum(singular > tolerance))
    with np.errstate(divide="ignore"):
        inverse = np.where(singular > tolerance, 1.0 / np.maximum(singular, tolerance) ** 2, np.inf)
    weight = vt.T**2
    variance = np.where(weight > 1e-12, weight * inverse[None, :], 0.0).sum(axis=1)
    norms = np.linalg.norm(jacobian, axis=0)
    scaled = np.linalg.svd(jacobian / np.where(norms > 0, norms, 1.0), compute_uv=False)
    condition = float(scaled.max() / scaled.min()) if scaled.min() > 0 else float("inf")
    return np.sqrt(variance), rank, condition


def still_gyro_bias(recording: Recording, intervals: Sequence[StaticInterval]) -> tuple[np.ndarray, np.ndarray,
                                                                                        np.ndarray]:
    """The gyro's bias as its still intervals give it alone (°/s: the weighted mean of their means, its 1σ
    for white noise, the per-sample noise): what the fit starts from, and all a recording without usable
    moves can say."""
    if recording.gyro_dps is None or not intervals:
        raise RecordingUnusable(f"{recording.source}: no gyro columns, or no static intervals")
    means, stderr, noise = _still_statistics(recording.gyro_dps, _sample_ranges(recording.t_s, intervals))
    return _weighted_mean(means, stderr) + (noise,)


def _weighted_mean(means: np.ndarray, stderr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per axis, the intervals' means weighted by 1/stderr² (for white noise, the mean of all still samples)
    and its 1σ."""
    weights = 1.0 / stderr**2
    return (means * weights).sum(axis=0) / weights.sum(axis=0), 1.0 / np.sqrt(weights.sum(axis=0))


@dataclass(frozen=True)
class _Still:
    """What the still intervals say alone: the bias, and G where they ask for it (per axis, weighted linear
    least squares of the intervals' means on 1 and f)."""

    bias_dps: np.ndarray
    bias_sigma_dps: np.ndarray
    gsens: np.ndarray          # (3, 3); zero unless fitted
    gsens_sigma: np.ndarray    # (3, 3); NaN unless fitted
    fitted: bool
    p_value: float | None      # None: the intervals' forces cannot separate G from the bias
    chi2_reduced: float | None
    note: str


def _still_fit(means: np.ndarray, stderr: np.ndarray, force_g: np.ndarray) -> _Still:
    """Bias alone against bias + G on the still intervals' means; G kept when the F-test on the drop in χ²
    rejects a gyro without one at GSENS_ALPHA, and only where the forces span space (four or more intervals not
    on one plane: else G and the bias cannot be told apart)."""
    bias, bias_sigma = _weighted_mean(means, stderr)
    chi2_bias = float(np.sum(((means - bias) / stderr) ** 2))
    n = len(means)
    design = np.column_stack([np.ones(n), force_g])
    dof = 3 * (n - 4)
    spread = np.linalg.svd(force_g - force_g.mean(axis=0), compute_uv=False) if n > 1 else np.zeros(0)
    chi2_bias_reduced = _dof_or_none(chi2_bias, 3 * n - 3)
    # The bias alone: its 1σ widened by √χ²_red where the intervals scatter more than their white noise says, as
    # the fit with the moves widens its own.
    bias_sigma = bias_sigma * math.sqrt(max(chi2_bias_reduced or 1.0, 1.0))
    if dof <= 0 or len(spread) < 3 or spread.min() < MIN_FORCE_SPREAD_G:
        return _Still(bias, bias_sigma, np.zeros((3, 3)), np.full((3, 3), np.nan), False, None, chi2_bias_reduced,
                      f"g-sensitivity not determinable from the {n} static intervals (their forces do not span "
                      "space beside the bias, or too few): not fitted, held at zero")
    coefficients, sigmas, chi2 = np.zeros((3, 4)), np.zeros((3, 4)), 0.0
    for axis in range(3):
        weighted = design / stderr[:, [axis]]
        target = means[:, axis] / stderr[:, axis]
        coefficients[axis] = np.linalg.lstsq(weighted, target, rcond=None)[0]
        sigmas[axis] = np.sqrt(np.diag(np.linalg.inv(weighted.T @ weighted)))
        chi2 += float(np.sum((weighted @ coefficients[axis] - target) ** 2))
    statistic = ((chi2_bias - chi2) / 9.0) / (chi2 / dof) if chi2 > 0 else math.inf
    p_value = float(f_distribution.sf(statistic, 9, dof))
    if p_value >= GSENS_ALPHA:
        return _Still(bias, bias_sigma, np.zeros((3, 3)), np.full((3, 3), np.nan), False, p_value, chi2_bias_reduced,
                      f"g-sensitivity not fitted: the still intervals' means do not depend on the force (F-test "
                      f"p = {p_value:.2g} ≥ {GSENS_ALPHA:g}); held at zero")
    scale = math.sqrt(max(chi2 / dof, 1.0))  # scatter beyond the white noise widens the 1σ, as the fit's does
    largest = float(np.abs(coefficients[:, 1:]).max())
    return _Still(coefficients[:, 0], sigmas[:, 0] * scale, coefficients[:, 1:], sigmas[:, 1:] * scale, True,
                  p_value, chi2 / dof,
                  f"g-sensitivity fitted: the still intervals' means depend on the force (F-test p = {p_value:.2g} < "
                  f"{GSENS_ALPHA:g}; largest term {largest:.3g} °/s per g)")


def _dof_or_none(chi2: float, dof: int) -> float | None:
    return chi2 / dof if dof > 0 else None


def fit_handheld_gyro(recording: Recording, intervals: Sequence[StaticInterval], gravity_direction: np.ndarray,
                      rate_hz: float | None = None, force_g: np.ndarray | None = None) -> HandheldGyroFit:
    """Bias, K and G of the recording's gyro from its static intervals and the moves between them.

    `gravity_direction` (len(intervals), 3): each interval's compensated accelerometer mean in g, in the frame K
    is wanted in (its direction closes the moves; the force itself is what G acts on). `force_g` (samples, 3):
    the compensated accelerometer at every sample, for G over the moves (the raw readings when not given).
    Where the moves cannot determine K (none turns the sensor, gravity turns further than the gyro says, a term
    left undetermined) the fit is of the still intervals alone, K nominal and said to be (`k_determined` False).
    """
    source = recording.source
    if recording.gyro_dps is None:
        raise RecordingUnusable(f"{source}: no gyro columns")
    if not intervals:
        raise RecordingUnusable(f"{source}: no static intervals: the gyro's bias needs the sensor held still")
    t = recording.t_s
    rate_hz = rate_hz or 1.0 / float(np.median(np.diff(t)))
    force_mean = np.asarray(gravity_direction, dtype=float)
    gravity = force_mean / np.linalg.norm(force_mean, axis=1, keepdims=True)
    force = recording.accel_g if force_g is None else np.asarray(force_g, dtype=float)
    ranges = _sample_ranges(t, intervals)
    means, stderr, noise = _still_statistics(recording.gyro_dps, ranges)
    still = _still_fit(means, stderr, force_mean)
    gravity_sigma = np.array([np.sqrt(np.mean(i.stderr_g**2)) / np.linalg.norm(i.mean_g) for i in intervals])
    moves, notes = _moves(recording, force, ranges, gravity_sigma, noise, rate_hz)
    notes.append(still.note)

    def still_only(reason: str, segments: int = 0) -> HandheldGyroFit:
        """The bias (and G) from the still intervals, K at the nominal sensitivity: all the data determine."""
        return HandheldGyroFit(
            still.bias_dps, np.eye(3), still.bias_sigma_dps, np.full((3, 3), np.nan), np.zeros(0), np.zeros(0),
            segments, np.zeros(0), noise, 0, math.nan, still.chi2_reduced,
            [f"K not determined, held at the nominal sensitivity: {reason}", *notes,
             f"bias from {len(intervals)} static intervals ({int((ranges[:, 1] - ranges[:, 0]).sum())} samples, noise "
             f"{np.mean(noise):.3g} °/s per sample); Earth's rate ({EARTH_RATE_DPS:.4f} °/s) not taken out"],
            still.gsens, still.gsens_sigma, still.fitted, still.p_value, k_determined=False)

    if len(moves.start) == 0:
        return still_only("no move between static intervals can be integrated")
    gsens_start = still.gsens
    identity = np.eye(3)
    bias_still = still.bias_dps
    before = _angles_deg(moves, gravity, bias_still, identity, gsens_start)
    gyro_turn = np.degrees(_turns(moves, bias_still, identity, gsens_start).magnitude())
    gravity_turn = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", gravity[moves.start],
                                                           gravity[moves.start + 1]), -1.0, 1.0)))
    reason = _turns_say_nothing(intervals, moves, gyro_turn, gravity_turn, _swept_deg(moves, bias_still))
    if reason:
        return still_only(reason, len(moves.start))

    bases = _tangent_bases(gravity[moves.start + 1])
    with_g = still.fitted

    def unpack(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return p[:3], p[3:12].reshape(3, 3), p[12:].reshape(3, 3) if with_g else _NO_GSENS

    def residuals(p: np.ndarray) -> np.ndarray:
        bias, matrix, gsens = unpack(p)
        closure = np.einsum("skj,sj->sk", bases, _misclosure(moves, gravity, bias, matrix, gsens))
        predicted = bias + force_mean @ gsens.T
        return np.concatenate([(closure / moves.sigma_rad[:, None]).ravel(), ((means - predicted) / stderr).ravel()])

    tail = [gsens_start.ravel()] if with_g else []
    starts = [np.concatenate([bias_still, m.ravel(), *tail]) for m in _signed_permutations()]
    start = min(starts, key=lambda p: float(np.sum(residuals(p) ** 2)))
    result = least_squares(residuals, start, x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    bias, matrix, gsens = unpack(result.x)
    sigma, rank, condition = _sigmas(result.jac)
    dof = len(result.fun) - len(result.x)
    chi2 = float(np.sum(result.fun**2) / dof) if dof > 0 else None
    if chi2 is not None and chi2 > 1.0:
        sigma = sigma * math.sqrt(chi2)
        notes.append(f"the residuals scatter more than the still intervals' white noise says (χ²_red {chi2:.3g}): "
                     f"1σ scaled by √χ²_red = {math.sqrt(chi2):.3g}")
    if not np.allclose(start[3:12], identity.ravel()):
        notes.append(f"the gyro's axes start from {_axis_map(start[3:12].reshape(3, 3))} of the accelerometer's (the "
                     "signed axis map that closes the moves best)")
    after = _angles_deg(moves, gravity, bias, matrix, gsens)
    undetermined = [name for name, s in zip(PARAMETER_NAMES[3:], sigma[3:12]) if not s <= MAX_SIGMA_MATRIX]
    if undetermined:
        return still_only(
            f"the {len(moves.start)} moves between static intervals do not determine the gyro's "
            f"{', '.join(undetermined)} (1σ over {MAX_SIGMA_MATRIX:.1%}; Jacobian rank {rank} of {len(result.x)}, "
            f"condition {condition:.3g}): turns about gravity, and full turns, are invisible to the gravity "
            "directions; turn the sensor by a quarter or half turn about each of its axes while it is not vertical",
            len(moves.start))
    turned = np.degrees(_turns(moves, bias, matrix, gsens).magnitude())
    bias_sigma_max = float(sigma[:3].max())
    earth = ("below the bias's 1σ ({:.2g} °/s): lost in the noise" if EARTH_RATE_DPS < bias_sigma_max else
             "above the bias's 1σ ({:.2g} °/s): part of the bias as fitted").format(bias_sigma_max)
    notes[:0] = [
        f"bias from {len(intervals)} static intervals ({int((ranges[:, 1] - ranges[:, 0]).sum())} samples, noise "
        f"{np.mean(noise):.3g} °/s per sample); Earth's rate ({EARTH_RATE_DPS:.4f} °/s) is {earth}, not taken out "
        "(that needs the latitude and each pose's heading)",
        f"K in the accelerometer's calibrated frame from {len(moves.start)} moves: each closes gravity's direction "
        f"(2 equations; the turn about gravity is invisible); all {len(result.x)} parameters determined (rank "
        f"{rank}, condition {condition:.3g})",
    ]
    gsens_sigma = sigma[12:].reshape(3, 3) if with_g else np.full((3, 3), np.nan)
    return HandheldGyroFit(bias, matrix, sigma[:3], sigma[3:12].reshape(3, 3), before, after, len(moves.start),
                           turned, noise, rank, condition, chi2, notes, gsens, gsens_sigma, with_g, still.p_value)


def _axis_map(matrix: np.ndarray) -> str:
    """[−x, −y, −z]: which accelerometer axis, and sign, each gyro axis reads."""
    return "[" + ", ".join(f"{'−' if row[np.argmax(np.abs(row))] < 0 else '+'}{AXES[int(np.argmax(np.abs(row)))]}"
                           for row in matrix) + "]"


def _turns_say_nothing(intervals: Sequence[StaticInterval], moves: _Moves, gyro_turn_deg: np.ndarray,
                       gravity_turn_deg: np.ndarray, swept_deg: np.ndarray) -> str:
    """Why the moves cannot calibrate K, in one sentence ("" when they can): none turns the sensor (a full turn
    ends where it began), or gravity turns further than the gyro says it did (a splice, another sensor's gyro,
    wrong units)."""
    if gyro_turn_deg.max() < MIN_TURN_DEG:
        full = (f", though one sweeps {swept_deg.max():.0f}° (a full turn ends where it began)"
                if swept_deg.max() > 180.0 else "")
        spliced = (f"; gravity turns up to {gravity_turn_deg.max():.0f}° meanwhile: a recording spliced from separate "
                   "poses, or the gyro units wrong?" if gravity_turn_deg.max() > MIN_TURN_DEG else "")
        return (f"no rotation between static intervals: the gyro's net turn is at most {gyro_turn_deg.max():.2g}° in "
                f"the {len(gyro_turn_deg)} moves between them{full}{spliced}; turn the sensor a quarter or half turn "
                "between still poses")
    impossible = np.flatnonzero(gravity_turn_deg > TURN_RATIO * gyro_turn_deg + TURN_SLACK_DEG)
    if len(impossible):
        k = int(impossible[0])
        leave, reach = intervals[moves.start[k]], intervals[moves.start[k] + 1]
        return (f"gravity turns {gravity_turn_deg[k]:.0f}° between the static intervals ending {leave.end_s:.2f} s and "
                f"starting {reach.start_s:.2f} s, the gyro only {gyro_turn_deg[k]:.1f}° ({len(impossible)} such moves "
                f"of {len(gyro_turn_deg)}): a splice in the recording, another sensor's gyro, or --gyro-units / "
                "--counts-per-dps wrong")
    return ""
