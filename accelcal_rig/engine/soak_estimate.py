"""How long a soak takes on the rig's model: the soak detector fed with what each DUT's part would read.

The band is a few of a part's temperature steps wide (an ADXL355's are 0.11 °C) and the reading noise moves
the moment it is met by minutes, so the soak is the median over `SOAK_DRAWS` draws of that noise.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.core.thermal import TEMPERATURE_READ_NOISE_C, ThermalModel
from accelcal_rig.engine.soak import first_stable_poll, settled_at
from accelcal_rig.parts.part import TemperatureFormat

#: Draws of the temperature reading noise over which the soak duration is a median.
SOAK_DRAWS = 9


def soak_duration(thermal: ThermalModel, procedure: Procedure, setpoint_c: float, t_reached_s: float,
                  readers: list[TemperatureFormat]) -> tuple[float, str, tuple[float, ...]]:
    """(soak duration s, outcome, settled DUT temperatures °C): the median over noise draws of the soak."""
    soak = procedure.soak
    n_polls = int(math.ceil(soak.timeout_min * 60.0 / soak.poll_s)) + 1
    t = np.minimum(t_reached_s + soak.poll_s * np.arange(n_polls), t_reached_s + soak.timeout_min * 60.0)
    ahead = copy.deepcopy(thermal)  # looks ahead to the deadline; the campaign's model stays at t_reached
    air, dut = np.empty(n_polls), np.empty((n_polls, len(thermal.dut_tau_s)))
    for k, ti in enumerate(t.tolist()):  # the model only advances: every query at one time before the next
        air[k], dut[k] = ahead.air_c(ti), ahead.duts_c(ti)
    rng = np.random.default_rng(0)
    outcomes = []
    for _ in range(SOAK_DRAWS):
        read = _as_read(dut + rng.normal(0.0, TEMPERATURE_READ_NOISE_C, dut.shape), readers)
        stable = first_stable_poll(soak, setpoint_c, t_reached_s, t, air, read)
        if stable is not None:
            outcomes.append((float(t[stable] - t_reached_s), "stable", settled_at(soak, t, read, stable)))
        else:
            outcomes.append((float(t[-1] - t_reached_s), "timeout", settled_at(soak, t, read, n_polls - 1)))
    soak_s, outcome, settled = sorted(outcomes, key=lambda o: o[0])[SOAK_DRAWS // 2]
    return soak_s, outcome, tuple(round(float(c), 3) for c in settled)


def _as_read(dut_c: np.ndarray, readers: list[TemperatureFormat]) -> np.ndarray:
    """Temperatures (polls × DUTs) as each DUT's temperature sensor reports them (its code, converted)."""
    read = np.empty_like(dut_c)
    for column, reader in enumerate(readers):
        read[:, column] = reader.celsius(reader.raw(dut_c[:, column]))
    return read
