"""Turntable motion: every axis moves at its own limited speed, then the table settles; a stop holds."""

from __future__ import annotations

import numpy as np


class TurntableMotion:
    """Angles in degrees, times in clock seconds. Final positions carry the table's accuracy error."""

    def __init__(self, speeds_deg_s: np.ndarray, accuracy_deg: float, settle_s: float,
                 rng: np.random.Generator) -> None:
        self.speeds_deg_s = np.asarray(speeds_deg_s, dtype=float)
        self.accuracy_deg = accuracy_deg
        self.settle_s = settle_s
        self._rng = rng
        self._start = np.zeros_like(self.speeds_deg_s)
        self._target = np.zeros_like(self.speeds_deg_s)
        self._t0 = 0.0
        self.last_command_deg: np.ndarray | None = None

    def position_deg(self, t_s: float) -> np.ndarray:
        travelled = self.speeds_deg_s * max(t_s - self._t0, 0.0)
        delta = self._target - self._start
        return self._start + np.sign(delta) * np.minimum(np.abs(delta), travelled)

    def command(self, t_s: float, target_deg: np.ndarray) -> None:
        self._start = self.position_deg(t_s)
        error = self._rng.uniform(-self.accuracy_deg, self.accuracy_deg, self._start.shape)
        self._target = np.asarray(target_deg, dtype=float) + error
        self._t0 = t_s
        self.last_command_deg = np.array(target_deg, dtype=float)

    def stop(self, t_s: float) -> None:
        self._start = self._target = self.position_deg(t_s)
        self._t0 = t_s

    def in_position(self, t_s: float) -> bool:
        travel_s = np.max(np.abs(self._target - self._start) / self.speeds_deg_s)
        return t_s >= self._t0 + travel_s + self.settle_s
