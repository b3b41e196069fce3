"""Soak criterion: when every DUT's own temperature has settled at a setpoint."""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.procedure import SoakCriterion


class SoakDetector:
    """Collects temperature polls from the moment the chamber reached its setpoint and judges stability.

    Stable when: the minimum dwell has passed; the polls cover a whole trailing window; within it the
    chamber air stayed within tolerance of the setpoint and each DUT's readings spanned at most the band.
    """

    def __init__(self, criterion: SoakCriterion, setpoint_c: float, t_reached_s: float) -> None:
        self.criterion = criterion
        self.setpoint_c = setpoint_c
        self.t_reached_s = t_reached_s
        self._t: list[float] = []
        self._chamber: list[float] = []
        self._dut: list[np.ndarray] = []

    def add(self, t_s: float, chamber_c: float, dut_c: np.ndarray) -> None:
        self._t.append(t_s)
        self._chamber.append(chamber_c)
        self._dut.append(np.asarray(dut_c, dtype=float))

    def _window(self) -> np.ndarray:
        t = np.asarray(self._t)
        return t >= t[-1] - self.criterion.window_min * 60.0

    def is_stable(self) -> bool:
        if not self._t:
            return False
        t = np.asarray(self._t)
        c = self.criterion
        if t[-1] - self.t_reached_s < c.min_dwell_min * 60.0 or t[-1] - t[0] < c.window_min * 60.0:
            return False
        window = self._window()
        chamber = np.asarray(self._chamber)[window]
        if np.any(np.abs(chamber - self.setpoint_c) > c.chamber_tolerance_c):
            return False
        return bool(np.all(self.dut_spans_c() <= c.band_c))

    def dut_spans_c(self) -> np.ndarray:
        """Max − min of each DUT's temperature over the trailing window."""
        dut = np.asarray(self._dut)[self._window()]
        return dut.max(axis=0) - dut.min(axis=0)

    def settled_dut_c(self) -> np.ndarray:
        """Each DUT's mean temperature over the trailing window."""
        return np.asarray(self._dut)[self._window()].mean(axis=0)

    def trace(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return np.asarray(self._t), np.asarray(self._chamber), np.asarray(self._dut)
