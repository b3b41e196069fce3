"""Chamber air and DUT temperatures: a rate-limited setpoint, a first-order air lag, first-order DUT lags.

Beyond that, each switched on by its own setting (docs/procedures.md, "Honest physics"): the controller's
overshoot where a ramp arrives (a share of the step, peaking three air time constants after arrival); a
cooling rate that falls towards the compressor's floor temperature; each slot's own air (the slots further
from the inlet nearer the ambient temperature); and a hysteresis state per DUT that swings towards its
direction of travel, a whole swing over `hysteresis_span_c` of travel, and relaxes with
`hysteresis_time_constant_s`.

Advanced lazily to the clock time of each query in sub-steps of at most `MAX_STEP_S`; each sub-step
solves the lag exactly for an input that is linear over it. Every DUT is advanced at once (numpy). The
number of sub-steps to reach a time is bounded by construction: at most one per `MAX_STEP_S`, plus one
where the ramp arrives (it then sits exactly on its target).
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

MAX_STEP_S = 10.0
#: A sub-step's change larger than this sets a DUT's direction of approach.
_DIRECTION_THRESHOLD_C = 1e-4


#: The controller's overshoot peaks this many air time constants after its ramp arrived.
OVERSHOOT_PEAK_TIME_CONSTANTS = 3.0

#: Noise of the DUT temperature reading before its 12-bit quantisation (dithers the 0.11 °C LSB).
TEMPERATURE_READ_NOISE_C = 0.05


def dut_time_constant_s(serial: str, fixture_tau_s: float) -> float:
    """Fixtures are never quite uniform: each DUT lags the air by its own ±10 % of the nominal constant."""
    spread = int.from_bytes(hashlib.sha256(f"tau:{serial}".encode()).digest()[:4], "little") / 2**32
    return fixture_tau_s * (0.9 + 0.2 * spread)


def _lag(state: np.ndarray | float, input_start: np.ndarray | float, input_end: np.ndarray | float, step_s: float,
         tau_s: np.ndarray | float) -> np.ndarray | float:
    """First-order lag after `step_s` with its input moving linearly from `input_start` to `input_end`."""
    slope = (input_end - input_start) / step_s
    return input_end - slope * tau_s + (state - input_start + slope * tau_s) * np.exp(-step_s / tau_s)


def _bump(u_s: float, tau_s: float) -> float:
    """An overshoot's shape after the ramp arrived: 0 at arrival, 1 at one time constant, then decaying."""
    return (u_s / tau_s) * math.exp(1.0 - u_s / tau_s) if u_s > 0 else 0.0


class ThermalModel:
    """Temperatures in °C, times in clock seconds."""

    def __init__(self, ambient_c: float, ramp_rate_c_per_s: float, chamber_tau_s: float,
                 dut_tau_s: list[float], self_heating_c: float, free_cooling_tau_s: float = 2700.0, *,
                 overshoot_fraction: float = 0.0, cooling_floor_c: float | None = None,
                 slot_offset_per_c: list[float] | None = None, hysteresis_span_c: float = 0.0,
                 hysteresis_time_constant_s: float | None = None, cooling_rate_c_per_s: float | None = None) -> None:
        self.ramp_rate_c_per_s = ramp_rate_c_per_s
        #: How fast it cools at the ambient temperature (None: as fast as it heats, `ramp_rate_c_per_s`).
        self.cooling_rate_c_per_s = ramp_rate_c_per_s if cooling_rate_c_per_s is None else cooling_rate_c_per_s
        self.overshoot_fraction = overshoot_fraction
        self.cooling_floor_c = cooling_floor_c
        #: Each slot's air: air + offset × (air − ambient) (0 for all: a uniform chamber).
        self.slot_offset_per_c = np.zeros(len(dut_tau_s)) if slot_offset_per_c is None else np.asarray(
            slot_offset_per_c, dtype=float)
        self.hysteresis_span_c = hysteresis_span_c
        self.hysteresis_time_constant_s = hysteresis_time_constant_s
        self.free_cooling_tau_s = free_cooling_tau_s
        self.chamber_tau_s = chamber_tau_s
        self.dut_tau_s = np.asarray(dut_tau_s, dtype=float)
        self.self_heating_c = self_heating_c
        self._t = 0.0
        self.ambient_c = ambient_c
        self.powered = True
        self.setpoint_c = ambient_c
        self._reference_c = ambient_c
        self._air_c = ambient_c
        self._dut_c = np.full(len(dut_tau_s), ambient_c + self_heating_c)
        #: Where the last ramp began and (once it arrived) when and by how much the air overshoots.
        self._ramp_from_c = ambient_c
        self._overshoot: tuple[float, float] | None = None
        #: Each DUT's hysteresis state in −1…+1: +1 after warming through `hysteresis_span_c`, −1 after
        #: cooling; what a hysteretic sensor remembers (with span 0: the sign of its last change).
        self.hysteresis_state = np.ones(len(dut_tau_s))
        #: Each DUT's rate of change over the last sub-step, °C/s.
        self.dut_rate_c_per_s = np.zeros(len(dut_tau_s))

    @property
    def approach_sign(self) -> np.ndarray:
        """+1 where a DUT last warmed, −1 where it last cooled (its hysteresis state's sign)."""
        return np.where(self.hysteresis_state >= 0, 1.0, -1.0)

    def set_setpoint(self, t_s: float, setpoint_c: float) -> None:
        self.advance_to(t_s)
        if setpoint_c != self.setpoint_c:
            self._ramp_from_c = self._reference_c
        self.setpoint_c = setpoint_c

    def set_power(self, t_s: float, on: bool) -> None:
        """A chamber switched off relaxes towards ambient with `free_cooling_tau_s` (its walls and load
        losing heat to the room), whatever its set point; switched on, it ramps to its set point again."""
        self.advance_to(t_s)
        self.powered = on

    @property
    def _target_c(self) -> float:
        return self.setpoint_c if self.powered else self.ambient_c

    def air_c(self, t_s: float) -> float:
        self.advance_to(t_s)
        return self._air_c

    def dut_c(self, t_s: float, index: int) -> float:
        self.advance_to(t_s)
        return float(self._dut_c[index])

    def duts_c(self, t_s: float) -> np.ndarray:
        """Every DUT's temperature at `t_s` (a copy)."""
        self.advance_to(t_s)
        return self._dut_c.copy()

    def ramp_rate_at_c_per_s(self, reference_c: float, cooling: bool) -> float:
        """How fast the chamber can move its air from `reference_c`: its heating rate, or its cooling rate, slower
        towards `cooling_floor_c` (a compressor's capacity falls with its evaporator temperature)."""
        if not cooling:
            return self.ramp_rate_c_per_s
        if self.cooling_floor_c is None or self.ambient_c <= self.cooling_floor_c:
            return self.cooling_rate_c_per_s
        share = (reference_c - self.cooling_floor_c) / (self.ambient_c - self.cooling_floor_c)
        return self.cooling_rate_c_per_s * float(np.clip(share, 0.05, 1.0))

    def advance_to(self, t_s: float) -> None:
        while self._t < t_s:
            step = min(MAX_STEP_S, t_s - self._t)
            gap = self._target_c - self._reference_c
            rate = self.ramp_rate_at_c_per_s(self._reference_c, gap < 0)
            arrives_s = abs(gap) / rate
            if self.powered and 0.0 < arrives_s <= step * (1.0 + 1e-9):  # end this sub-step where the ramp arrives
                step = arrives_s  # (also when it arrives just at the sub-step's end: its overshoot starts there)
            self._step(step, rate, arrives=self.powered and 0.0 < arrives_s <= step)
            self._t = t_s if step >= t_s - self._t else self._t + step

    def _step(self, step_s: float, rate_c_per_s: float, arrives: bool) -> None:
        gap = self._target_c - self._reference_c
        if arrives:
            reference_end = self._target_c
        elif self.powered:
            reference_end = self._reference_c + math.copysign(rate_c_per_s * step_s, gap) if gap else self._reference_c
        else:
            reference_end = self.ambient_c - gap * math.exp(-step_s / self.free_cooling_tau_s)
        t_end = self._t + step_s
        if arrives and self.overshoot_fraction:
            self._overshoot = (t_end, self.overshoot_fraction * (self._target_c - self._ramp_from_c))
        if not self.powered:
            self._overshoot = None
        air_end = float(_lag(self._air_c, self._reference_c + self._overshoot_c(self._t),
                             reference_end + self._overshoot_c(t_end), step_s, self.chamber_tau_s))
        offsets = self.slot_offset_per_c
        target_start = self._air_c + offsets * (self._air_c - self.ambient_c) + self.self_heating_c
        target_end = air_end + offsets * (air_end - self.ambient_c) + self.self_heating_c
        new_dut_c = np.asarray(_lag(self._dut_c, target_start, target_end, step_s, self.dut_tau_s))
        change = new_dut_c - self._dut_c
        self._remember_direction(change, step_s)
        self.dut_rate_c_per_s = change / step_s
        self._dut_c = new_dut_c
        self._reference_c = reference_end
        self._air_c = air_end

    def _overshoot_c(self, t_s: float) -> float:
        """How far the controller drives past its set point at `t_s` after a ramp arrived: the share of the
        step, peaking `OVERSHOOT_PEAK_TIME_CONSTANTS` air time constants after arrival (the air, lagging,
        overshoots by somewhat less)."""
        if self._overshoot is None:
            return 0.0
        return self._overshoot[1] * _bump(t_s - self._overshoot[0], OVERSHOOT_PEAK_TIME_CONSTANTS * self.chamber_tau_s)

    def _remember_direction(self, change: np.ndarray, step_s: float) -> None:
        """Move each hysteresis state with the temperature: a whole swing, −1 to +1, over
        `hysteresis_span_c` of travel (at once with span 0); then let it relax."""
        if self.hysteresis_span_c > 0:
            self.hysteresis_state = np.clip(self.hysteresis_state + 2.0 * change / self.hysteresis_span_c, -1.0, 1.0)
        else:
            moved = np.abs(change) > _DIRECTION_THRESHOLD_C
            self.hysteresis_state = np.where(moved, np.sign(change), self.hysteresis_state)
        if self.hysteresis_time_constant_s is not None:
            self.hysteresis_state = self.hysteresis_state * math.exp(-step_s / self.hysteresis_time_constant_s)
