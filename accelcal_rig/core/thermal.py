"""Chamber air and DUT temperatures: a rate-limited setpoint, a first-order air lag, first-order DUT lags.

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


#: Noise of the DUT temperature reading before its 12-bit quantisation (dithers the 0.11 °C LSB).
TEMPERATURE_READ_NOISE_C = 0.05


def dut_time_constant_s(serial: str, fixture_tau_s: float) -> float:
    """Fixtures are never quite uniform: each DUT lags the air by its own ±10 % of the nominal constant."""
    spread = int.from_bytes(hashlib.sha256(f"tau:{serial}".encode()).digest()[:4], "little") / 2**32
    return fixture_tau_s * (0.9 + 0.2 * spread)


def _lag(state: np.ndarray | float, input_start: float, input_end: float, step_s: float,
         tau_s: np.ndarray | float) -> np.ndarray | float:
    """First-order lag after `step_s` with its input moving linearly from `input_start` to `input_end`."""
    slope = (input_end - input_start) / step_s
    return input_end - slope * tau_s + (state - input_start + slope * tau_s) * np.exp(-step_s / tau_s)


class ThermalModel:
    """Temperatures in °C, times in clock seconds."""

    def __init__(self, ambient_c: float, ramp_rate_c_per_s: float, chamber_tau_s: float,
                 dut_tau_s: list[float], self_heating_c: float, free_cooling_tau_s: float = 2700.0) -> None:
        self.ramp_rate_c_per_s = ramp_rate_c_per_s
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
        #: +1 if each DUT last moved up in temperature, −1 if down: what a hysteretic sensor remembers.
        self.approach_sign = np.ones(len(dut_tau_s))

    def set_setpoint(self, t_s: float, setpoint_c: float) -> None:
        self.advance_to(t_s)
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

    def advance_to(self, t_s: float) -> None:
        while self._t < t_s:
            step = min(MAX_STEP_S, t_s - self._t)
            gap = self._target_c - self._reference_c
            arrives_s = abs(gap) / self.ramp_rate_c_per_s
            if self.powered and 0.0 < arrives_s < step:  # end this sub-step where the ramp arrives
                step = arrives_s
            self._step(step, arrives=self.powered and arrives_s <= step)
            self._t = t_s if step >= t_s - self._t else self._t + step

    def _step(self, step_s: float, arrives: bool) -> None:
        gap = self._target_c - self._reference_c
        if arrives:
            reference_end = self._target_c
        elif self.powered:
            reference_end = self._reference_c + math.copysign(self.ramp_rate_c_per_s * step_s, gap)
        else:
            reference_end = self.ambient_c - gap * math.exp(-step_s / self.free_cooling_tau_s)
        air_end = float(_lag(self._air_c, self._reference_c, reference_end, step_s, self.chamber_tau_s))
        target_start = self._air_c + self.self_heating_c
        target_end = air_end + self.self_heating_c
        new_dut_c = _lag(self._dut_c, target_start, target_end, step_s, self.dut_tau_s)
        change = new_dut_c - self._dut_c
        self.approach_sign = np.where(np.abs(change) > _DIRECTION_THRESHOLD_C, np.sign(change), self.approach_sign)
        self._dut_c = np.asarray(new_dut_c)
        self._reference_c = reference_end
        self._air_c = air_end
