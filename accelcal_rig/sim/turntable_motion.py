"""Turntable motion: every axis moves at its own limited speed, then the table settles; a stop holds.

Axes are commanded one at a time (line protocols move one axis per command) or all together.
"""

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
        n = len(self.speeds_deg_s)
        self._start = np.zeros(n)
        self._target = np.zeros(n)
        self._t0 = np.full(n, -1e9)  # at rest and settled since long before the clock started
        self.last_command_deg = np.full(n, np.nan)

    def position_deg(self, t_s: float) -> np.ndarray:
        travelled = self.speeds_deg_s * np.maximum(t_s - self._t0, 0.0)
        delta = self._target - self._start
        return self._start + np.sign(delta) * np.minimum(np.abs(delta), travelled)

    def rate_deg_s(self, t_s: float) -> np.ndarray:
        """Each axis's rate now: its speed while it travels, zero once it has arrived."""
        travelling = np.abs(self._target - self._start) > self.speeds_deg_s * np.maximum(t_s - self._t0, 0.0)
        return np.where(travelling, np.sign(self._target - self._start) * self.speeds_deg_s, 0.0)

    def command_axis(self, t_s: float, axis: int, target_deg: float) -> None:
        self._start[axis] = self.position_deg(t_s)[axis]
        self._target[axis] = target_deg + self._rng.uniform(-self.accuracy_deg, self.accuracy_deg)
        self._t0[axis] = t_s
        self.last_command_deg[axis] = target_deg

    def command(self, t_s: float, target_deg: np.ndarray) -> None:
        for axis, target in enumerate(np.asarray(target_deg, dtype=float)):
            self.command_axis(t_s, axis, float(target))

    def stop(self, t_s: float) -> None:
        here = self.position_deg(t_s)
        self._start, self._target = here.copy(), here.copy()
        self._t0 = np.full_like(self._t0, t_s)

    def in_position(self, t_s: float, axis: int | None = None) -> bool:
        """Arrived and settled: every axis, or the one given."""
        arrival = self._t0 + np.abs(self._target - self._start) / self.speeds_deg_s
        return t_s >= (arrival.max() if axis is None else arrival[axis]) + self.settle_s
