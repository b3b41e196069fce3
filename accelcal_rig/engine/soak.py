"""Soak criteria: when every DUT's own temperature has settled at a setpoint.

Stable at a poll when: the minimum dwell has passed since the chamber reached the setpoint; the polls
cover a whole trailing window; within that window the chamber air stayed within tolerance of the
setpoint; and each DUT's readings over the window pass the criterion:

- `band`: they span at most `band_c`. A span of noisy readings grows with their number, so a faster poll
  or a larger fixture makes the soak longer (and a 64-DUT fixture's soak a lottery of minutes to hours).
- `settling`: a settling curve T(t) = a + b·exp(−(t − now)/τ) per DUT, its τ the one of a geometric grid
  that fits the DUT's whole soak best, a and b fitted over the window by least squares. |b| is the change still to come and
  |b|/τ the rate now; each bound is the estimate plus twice its standard error. More polls narrow the
  bounds, never widen them: the moment does not depend on the poll rate, to first order.

`SoakDetector` judges poll by poll as a campaign runs (each judgement costs the window, not the soak so
far); `first_stable_poll` judges the polls of a whole trace, for the duration estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import maximum_filter1d, minimum_filter1d

from accelcal_rig.config.procedure import SoakCriterion

#: Window lengths (in polls) judged with running filters; rarer ones (the poll cut short at a deadline)
#: one by one. Evenly spaced polls give one or two lengths, rounding the window to whole polls.
_FILTERED_LENGTHS = 4
#: Settling time constants tried, geometrically spaced from a few polls to `time_constant_max_min`.
_TIME_CONSTANTS = 24
#: Coverage factor of the settling bounds.
_K = 2.0
#: Fewest polls in the window the settling criterion judges (two parameters, and their scatter).
MIN_WINDOW_POLLS = 5


@dataclass(frozen=True)
class Settling:
    """A settling curve fitted to each DUT's readings over a window (arrays over the DUTs)."""

    time_constant_s: np.ndarray
    remaining_c: np.ndarray       # |b| + k·σ_b: how much each DUT may still change
    rate_c_per_min: np.ndarray    # (|b| + k·σ_b) / τ: how fast it may be moving now
    now_c: np.ndarray             # a + b: the fitted temperature at the last poll

    def settled(self, criterion: SoakCriterion) -> bool:
        return bool(np.all(self.remaining_c <= criterion.settle_c)
                    and np.all(self.rate_c_per_min <= criterion.max_rate_c_per_min))


def is_settled(criterion: SoakCriterion, t_s: np.ndarray, dut_c: np.ndarray, window_start: int) -> bool:
    """`fit_settling(...).settled(criterion)`, the curves fitted only once a straight line through the window
    is slow enough: its rate bound is part of the curve's, and rejecting on it alone costs a fraction of the
    fit (the duration estimate judges every poll of every soak many times)."""
    if len(t_s) - window_start < MIN_WINDOW_POLLS:
        return False
    line_c_per_min = 60.0 * _line_rate_bound(t_s[window_start:], dut_c[window_start:])
    if np.any(line_c_per_min > criterion.max_rate_c_per_min):
        return False
    return fit_settling(criterion, t_s, dut_c, window_start).settled(criterion)


def fit_settling(criterion: SoakCriterion, t_s: np.ndarray, dut_c: np.ndarray, window_start: int) -> Settling:
    """Each DUT's τ from every poll of the soak (the one of the grid whose a + B·exp(−t/τ) fits it best: the
    approach, large early on, fixes it), then a and b over the polls from `window_start` with that τ, or half
    the window if that is longer (a τ much shorter than the window would leave b ≈ 0 whatever the window
    holds); a linear fit, so its b and σ_b carry no bias from choosing τ on the same noise. The rate bound is
    also that of a straight line through the window (a drift or a wobble the curve would not follow). Fewer
    than MIN_WINDOW_POLLS polls in the window: nothing is known (infinite bounds)."""
    n = len(t_s) - window_start
    if n < MIN_WINDOW_POLLS:
        unknown = np.full(dut_c.shape[1], np.inf)
        return Settling(unknown, unknown, unknown, dut_c[-1].astype(float))
    taus = _time_constants(criterion, t_s)
    best = np.argmin(_least_squares(t_s, dut_c - dut_c.mean(axis=0), taus)[2], axis=0)   # per DUT
    t_window, y_window = t_s[window_start:], dut_c[window_start:]
    shortest = int(np.searchsorted(taus, 0.5 * (t_window[-1] - t_window[0])))
    chosen = np.minimum(np.maximum(best, shortest), len(taus) - 1)
    offset = y_window.mean(axis=0)
    big_a, big_b, sse, det = (v[chosen, np.arange(len(chosen))] for v in _least_squares(t_window, y_window - offset,
                                                                                          taus))
    last = np.exp(-(t_window[-1] - t_window[0]) / taus[chosen])
    b = big_b * last
    sigma_b = np.sqrt(np.maximum(sse, 0.0) / (n - 2) * n / det) * last
    bound = np.abs(b) + _K * sigma_b
    return Settling(taus[chosen], bound, np.maximum(bound / taus[chosen], _line_rate_bound(t_window, y_window)) * 60.0,
                    big_a + b + offset)


def _line_rate_bound(t_s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """|slope| + k·σ of a straight line through each DUT's readings, °C/s."""
    dt = t_s - t_s.mean()
    sxx = float(dt @ dt)
    slope = dt @ (y - y.mean(axis=0)) / sxx
    residual = y - y.mean(axis=0) - np.outer(dt, slope)
    sigma = np.sqrt(np.einsum("ij,ij->j", residual, residual) / (len(t_s) - 2) / sxx)
    return np.abs(slope) + _K * sigma


def _time_constants(criterion: SoakCriterion, t_s: np.ndarray) -> np.ndarray:
    """The grid of τ tried: from two poll intervals to `time_constant_max_min`."""
    spacing_s = (t_s[-1] - t_s[0]) / max(len(t_s) - 1, 1)
    shortest_s = max(2.0 * spacing_s, 1.0)
    return np.geomspace(shortest_s, max(criterion.time_constant_max_min * 60.0, 2.0 * shortest_s), _TIME_CONSTANTS)


def _least_squares(t_s: np.ndarray, y: np.ndarray, taus: np.ndarray) -> tuple[np.ndarray, ...]:
    """(a, B, residual sum of squares, det of the normal matrix) of y ≈ a + B·exp(−(t − t_first)/τ), for every
    τ (rows) and DUT (columns) at once: the design is the same for every DUT, so only sums are formed
    (σ_B² = s² n / det). `y` is best centred: the sums then lose nothing to cancellation."""
    e = np.exp(-(np.asarray(t_s, dtype=float) - t_s[0])[None, :] / taus[:, None])   # (τ, polls), 1 at the first
    n = e.shape[1]
    sum_e, sum_ee = e.sum(axis=1), np.einsum("ki,ki->k", e, e)
    det = np.maximum(n * sum_ee - sum_e**2, 1e-300)
    sum_y, sum_ey, sum_yy = y.sum(axis=0), e @ y, np.einsum("ij,ij->j", y, y)
    big_b = (n * sum_ey - sum_e[:, None] * sum_y[None, :]) / det[:, None]
    a = (sum_y[None, :] - big_b * sum_e[:, None]) / n
    sse = sum_yy[None, :] - a * sum_y[None, :] - big_b * sum_ey
    return a, big_b, sse, det[:, None] * np.ones_like(big_b)


class SoakDetector:
    """Collects temperature polls from the moment the chamber reached its setpoint and judges stability."""

    def __init__(self, criterion: SoakCriterion, setpoint_c: float, t_reached_s: float) -> None:
        self.criterion = criterion
        self.setpoint_c = setpoint_c
        self.t_reached_s = t_reached_s
        self._n = 0
        self._t = np.empty(64)
        self._chamber = np.empty(64)
        self._dut: np.ndarray | None = None

    def add(self, t_s: float, chamber_c: float, dut_c: np.ndarray) -> None:
        dut_c = np.asarray(dut_c, dtype=float)
        if self._dut is None:
            self._dut = np.empty((len(self._t), len(dut_c)))
        if self._n == len(self._t):  # grow by doubling: adding stays cheap however long the soak
            self._t, self._chamber = np.resize(self._t, 2 * self._n), np.resize(self._chamber, 2 * self._n)
            self._dut = np.resize(self._dut, (2 * self._n, self._dut.shape[1]))
        self._t[self._n], self._chamber[self._n], self._dut[self._n] = t_s, chamber_c, dut_c
        self._n += 1

    def _window(self) -> slice:
        t = self._t[:self._n]
        return slice(int(np.searchsorted(t, t[-1] - self.criterion.window_min * 60.0, side="left")), self._n)

    def is_stable(self) -> bool:
        if not self._n:
            return False
        c = self.criterion
        t = self._t[:self._n]
        if t[-1] - self.t_reached_s < c.min_dwell_min * 60.0 or t[-1] - t[0] < c.window_min * 60.0:
            return False
        window = self._window()
        if np.any(np.abs(self._chamber[window] - self.setpoint_c) > c.chamber_tolerance_c):
            return False
        if c.criterion == "settling":
            assert self._dut is not None
            return is_settled(c, t, self._dut[:self._n], window.start)
        return bool(np.all(self.dut_spans_c() <= c.band_c))

    def settling(self) -> Settling:
        """The settling curve: τ from the whole soak, the rest from the trailing window."""
        assert self._dut is not None
        return fit_settling(self.criterion, self._t[:self._n], self._dut[:self._n], self._window().start)

    def dut_spans_c(self) -> np.ndarray:
        """Max − min of each DUT's temperature over the trailing window."""
        assert self._dut is not None
        dut = self._dut[self._window()]
        return dut.max(axis=0) - dut.min(axis=0)

    def settled_dut_c(self) -> np.ndarray:
        """Each DUT's temperature where it settled: the mean over the trailing window (band), the fitted
        curve's value at the last poll (settling: the mean would lag a DUT still creeping)."""
        assert self._dut is not None
        if self.criterion.criterion == "settling" and self._window().stop - self._window().start >= MIN_WINDOW_POLLS:
            return self.settling().now_c
        return self._dut[self._window()].mean(axis=0)

    def trace(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        dut = self._dut[:self._n] if self._dut is not None else np.zeros((0, 0))
        return self._t[:self._n].copy(), self._chamber[:self._n].copy(), dut.copy()


def first_stable_poll(criterion: SoakCriterion, setpoint_c: float, t_reached_s: float, t_s: np.ndarray,
                      chamber_c: np.ndarray, dut_c: np.ndarray) -> int | None:
    """The first poll at which a SoakDetector fed these polls in order would be stable (None: never).

    Vectorised over the polls: the trailing window's extremes come from running max/min filters, which
    need a constant window length, so polls whose window holds another number of polls (the last one,
    cut short at a deadline) are judged one by one.
    """
    n = len(t_s)
    if not n:
        return None
    window_s = criterion.window_min * 60.0
    start = np.searchsorted(t_s, t_s - window_s, side="left")
    index = np.arange(n)
    length = index - start + 1
    candidate = (t_s - t_reached_s >= criterion.min_dwell_min * 60.0) & (t_s - t_s[0] >= window_s)
    outside = np.concatenate([[0], np.cumsum(np.abs(chamber_c - setpoint_c) > criterion.chamber_tolerance_c)])
    candidate &= outside[index + 1] - outside[start] == 0
    if not candidate.any():
        return None
    if criterion.criterion == "settling":  # a fit per poll, in order, until one settles
        for k in np.flatnonzero(candidate & (length >= MIN_WINDOW_POLLS)):
            if is_settled(criterion, t_s[:k + 1], dut_c[:k + 1], int(start[k])):
                return int(k)
        return None
    settled = np.zeros(n, dtype=bool)
    values, counts = np.unique(length[candidate], return_counts=True)
    lengths = values[np.argsort(-counts, kind="stable")]  # the most common first
    for width in lengths[:_FILTERED_LENGTHS]:  # each window length its own running filter
        rows = candidate & (length == width)
        # A running filter of size w centred at c covers [c − w//2, c − w//2 + w − 1]: the window ending at
        # k is centred at k − w + 1 + w//2.
        centre = np.clip(index[rows] - width + 1 + width // 2, 0, n - 1)
        span = (maximum_filter1d(dut_c, int(width), axis=0, mode="nearest") -
                minimum_filter1d(dut_c, int(width), axis=0, mode="nearest"))[centre]
        settled[rows] = np.all(span <= criterion.band_c, axis=1)
    for k in np.flatnonzero(candidate & np.isin(length, lengths[_FILTERED_LENGTHS:])):  # rare lengths, directly
        window = dut_c[start[k]:k + 1]
        settled[k] = bool(np.all(window.max(axis=0) - window.min(axis=0) <= criterion.band_c))
    found = np.flatnonzero(settled)
    return int(found[0]) if len(found) else None


def settled_at(criterion: SoakCriterion, t_s: np.ndarray, dut_c: np.ndarray, poll: int) -> np.ndarray:
    """What the detector reports as settled over the trailing window ending at `poll`."""
    start = int(np.searchsorted(t_s[:poll + 1], t_s[poll] - criterion.window_min * 60.0, side="left"))
    if criterion.criterion == "settling" and poll + 1 - start >= MIN_WINDOW_POLLS:
        return fit_settling(criterion, t_s[:poll + 1], dut_c[:poll + 1], start).now_c
    return dut_c[start:poll + 1].mean(axis=0)
