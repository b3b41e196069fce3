"""Turntable motion: every axis moves at its own limited speed, then the table settles; a stop holds.

Axes are commanded one at a time (line protocols move one axis per command) or all together. An axis may
instead turn at a constant rate (a rate table): it accelerates at the commanded limit to the commanded rate,
off by the table's rate accuracy, and its angle keeps integrating; a hold (or a stop) decelerates it to rest
at the same limit. A position command after that takes the shortest way from where the axis stands, as a
continuous axis does: its angle read back is then within a turn of the target again.
"""

from __future__ import annotations

import numpy as np


class TurntableMotion:
    """Angles in degrees, times in clock seconds. Final positions carry the table's accuracy error."""

    def __init__(self, speeds_deg_s: np.ndarray, accuracy_deg: float, settle_s: float,
                 rng: np.random.Generator, rate_offsets: np.ndarray | None = None,
                 rate_stability: float = 0.0, rate_rng: np.random.Generator | None = None) -> None:
        self.speeds_deg_s = np.asarray(speeds_deg_s, dtype=float)
        self.accuracy_deg = accuracy_deg
        self.settle_s = settle_s
        self._rng = rng
        n = len(self.speeds_deg_s)
        self._start = np.zeros(n)
        self._target = np.zeros(n)
        self._t0 = np.full(n, -1e9)  # at rest and settled since long before the clock started
        self.last_command_deg = np.full(n, np.nan)
        #: Each axis's rate error as a fraction of its rate (the table's rate accuracy), and the relative
        #: standard deviation of each rate read back (its stability), drawn from their own stream.
        self.rate_offsets = np.zeros(n) if rate_offsets is None else np.asarray(rate_offsets, dtype=float)
        self.rate_stability = rate_stability
        self._rate_rng = rate_rng if rate_rng is not None else np.random.default_rng(0)
        # Rate mode, per axis: since when, from which angle and rate, to which rate, at which acceleration.
        self._rating = np.zeros(n, dtype=bool)
        self._r_t0 = np.zeros(n)
        self._r_angle0 = np.zeros(n)
        self._r_from = np.zeros(n)
        self._r_to = np.zeros(n)
        self._r_acc = np.ones(n)
        #: The last rate commanded on each axis (°/s; NaN: never), for tests.
        self.last_rate_command_deg_s = np.full(n, np.nan)

    def position_deg(self, t_s: float) -> np.ndarray:
        travelled = self.speeds_deg_s * np.maximum(t_s - self._t0, 0.0)
        delta = self._target - self._start
        here = self._start + np.sign(delta) * np.minimum(np.abs(delta), travelled)
        for axis in np.flatnonzero(self._rating):
            here[axis] = self._rate_state(int(axis), t_s)[0]
        return here

    def rate_deg_s(self, t_s: float) -> np.ndarray:
        """Each axis's rate now: its speed while it travels, zero once it has arrived; in rate mode its
        ramped rate."""
        travelling = np.abs(self._target - self._start) > self.speeds_deg_s * np.maximum(t_s - self._t0, 0.0)
        rates = np.where(travelling, np.sign(self._target - self._start) * self.speeds_deg_s, 0.0)
        for axis in np.flatnonzero(self._rating):
            rates[axis] = self._rate_state(int(axis), t_s)[1]
        return rates

    def path_deg(self, times_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every axis's angle and rate at each of `times_s` (shapes (n, axes)), as `position_deg` and
        `rate_deg_s` give them one time at a time: what the samples of a record taken while the table turns
        felt, sample by sample."""
        times = np.asarray(times_s, dtype=float)[:, None]
        elapsed = np.maximum(times - self._t0, 0.0)
        delta = self._target - self._start
        travelled = self.speeds_deg_s * elapsed
        angles = self._start + np.sign(delta) * np.minimum(np.abs(delta), travelled)
        rates = np.where(np.abs(delta) > travelled, np.sign(delta) * self.speeds_deg_s, 0.0)
        for axis in np.flatnonzero(self._rating):
            dt = np.maximum(times[:, 0] - self._r_t0[axis], 0.0)
            start, end, acc = self._r_from[axis], self._r_to[axis], self._r_acc[axis]
            ramp_s = abs(end - start) / acc
            sign = np.sign(end - start)
            ramping = dt <= ramp_s
            angles[:, axis] = np.where(ramping, self._r_angle0[axis] + start * dt + 0.5 * sign * acc * dt * dt,
                                       self._r_angle0[axis] + 0.5 * (start + end) * ramp_s + end * (dt - ramp_s))
            rates[:, axis] = np.where(ramping, start + sign * acc * dt, end)
        return angles, rates

    def read_rate_deg_s(self, t_s: float, axis: int) -> float:
        """The rate a controller reads back for one axis: in rate mode with the table's wobble (its own
        stream, drawn only for an axis in rate mode), else as `rate_deg_s`."""
        rate = float(self.rate_deg_s(t_s)[axis])
        if self._rating[axis] and self.rate_stability > 0 and rate != 0.0:
            rate += abs(rate) * self.rate_stability * float(self._rate_rng.normal())
        return rate

    def command_axis(self, t_s: float, axis: int, target_deg: float) -> None:
        here = self.position_deg(t_s)[axis]
        target = target_deg + self._rng.uniform(-self.accuracy_deg, self.accuracy_deg)
        if self._rating[axis]:  # out of rate mode: the shortest way, from the same angle a whole number of turns off
            self._rating[axis] = False
            here = target + (here - target + 180.0) % 360.0 - 180.0
        self._start[axis] = here
        self._target[axis] = target
        self._t0[axis] = t_s
        self.last_command_deg[axis] = target_deg

    def command(self, t_s: float, target_deg: np.ndarray) -> None:
        for axis, target in enumerate(np.asarray(target_deg, dtype=float)):
            self.command_axis(t_s, axis, float(target))

    def rotate(self, t_s: float, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        """Rate mode: accelerate from the axis's rate now to `rate_deg_s` (off by its rate accuracy)."""
        angle, rate = self.position_deg(t_s)[axis], self.rate_deg_s(t_s)[axis]
        self._rating[axis] = True
        self._r_t0[axis], self._r_angle0[axis], self._r_from[axis] = t_s, angle, rate
        self._r_to[axis] = rate_deg_s * (1.0 + self.rate_offsets[axis])
        self._r_acc[axis] = acceleration_deg_s2
        self.last_rate_command_deg_s[axis] = rate_deg_s

    def hold(self, t_s: float, axis: int) -> None:
        """Decelerate an axis in rate mode to rest at its acceleration limit, where it then holds."""
        if self._rating[axis]:
            self.rotate(t_s, axis, 0.0, float(self._r_acc[axis]))

    def halt(self, t_s: float, axis: int) -> None:
        """One axis brought to rest where it is: in rate mode at its acceleration limit (a hold), a position move
        stopped where it has got to (the table's travel has no acceleration phase to ramp down)."""
        if self._rating[axis]:
            self.hold(t_s, axis)
            return
        here = float(self.position_deg(t_s)[axis])
        self._start[axis] = self._target[axis] = here
        self._t0[axis] = t_s

    def acceleration_deg_s2(self, t_s: float, axis: int) -> float:
        """An axis's acceleration now: its ramp's while a rate-mode axis changes rate, else zero (a position
        move travels at its speed from the start: no acceleration phase is modelled)."""
        if not self._rating[axis]:
            return 0.0
        start, end, acc = self._r_from[axis], self._r_to[axis], self._r_acc[axis]
        ramping = t_s - self._r_t0[axis] < abs(end - start) / acc
        return float(np.sign(end - start) * acc) if ramping else 0.0

    def stop(self, t_s: float) -> None:
        here = self.position_deg(t_s)
        for axis in np.flatnonzero(self._rating):
            self.hold(t_s, int(axis))
        self._start, self._target = here.copy(), here.copy()
        self._t0 = np.full_like(self._t0, t_s)

    def in_position(self, t_s: float, axis: int | None = None) -> bool:
        """Arrived and settled: every axis, or the one given (an axis in rate mode once it has come to rest)."""
        arrival = self._t0 + np.abs(self._target - self._start) / self.speeds_deg_s
        for a in np.flatnonzero(self._rating):
            arrival[a] = (self._r_t0[a] + abs(self._r_to[a] - self._r_from[a]) / self._r_acc[a]
                          if self._r_to[a] == 0.0 else np.inf)
        return t_s >= (arrival.max() if axis is None else arrival[axis]) + self.settle_s

    def _rate_state(self, axis: int, t_s: float) -> tuple[float, float]:
        """(angle, rate) of an axis in rate mode: a ramp at its acceleration, then its rate."""
        dt = max(t_s - self._r_t0[axis], 0.0)
        start, end, acc = self._r_from[axis], self._r_to[axis], self._r_acc[axis]
        ramp_s = abs(end - start) / acc
        sign = np.sign(end - start)
        angle0 = self._r_angle0[axis]
        if dt <= ramp_s:
            return float(angle0 + start * dt + 0.5 * sign * acc * dt * dt), float(start + sign * acc * dt)
        return float(angle0 + 0.5 * (start + end) * ramp_s + end * (dt - ramp_s)), float(end)
