"""Soak criterion: when every DUT's own temperature has settled at a setpoint.

Stable at a poll when: the minimum dwell has passed since the chamber reached the setpoint; the polls
cover a whole trailing window; within that window the chamber air stayed within tolerance of the
setpoint and each DUT's readings spanned at most the band. `SoakDetector` judges it poll by poll as a
campaign runs (each judgement costs the window, not the soak so far); `first_stable_poll` judges every
poll of a whole trace at once, for the duration estimate.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d, minimum_filter1d

from accelcal_rig.config.procedure import SoakCriterion

#: Window lengths (in polls) judged with running filters; rarer ones (the poll cut short at a deadline)
#: one by one. Evenly spaced polls give one or two lengths, rounding the window to whole polls.
_FILTERED_LENGTHS = 4


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
        return bool(np.all(self.dut_spans_c() <= c.band_c))

    def dut_spans_c(self) -> np.ndarray:
        """Max − min of each DUT's temperature over the trailing window."""
        assert self._dut is not None
        dut = self._dut[self._window()]
        return dut.max(axis=0) - dut.min(axis=0)

    def settled_dut_c(self) -> np.ndarray:
        """Each DUT's mean temperature over the trailing window."""
        assert self._dut is not None
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
    """Each DUT's mean over the trailing window ending at `poll` (what the detector reports as settled)."""
    start = int(np.searchsorted(t_s[:poll + 1], t_s[poll] - criterion.window_min * 60.0, side="left"))
    return dut_c[start:poll + 1].mean(axis=0)
