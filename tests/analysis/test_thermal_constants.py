"""The rig's thermal constants fitted to ramps and soaks: recovered from traces the thermal model made with
constants the fit was not told, noise included; and a campaign without kept ramps refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.analysis.thermal_constants import fit_thermal_constants
from accelcal_rig.core.thermal import ThermalModel
from accelcal_rig.store.records import SoakTrace

#: What the traces are made with (the fit is told none of it).
TRUE = {"heating_c_per_min": 2.5, "cooling_c_per_min": 2.0, "floor_c": -80.0, "air_tau_min": 4.0,
        "overshoot": 0.03, "dut_tau_min": (7.0, 12.0), "room_c": 22.0}
POLL_S = 10.0
NOISE_C = 0.05


def traces(setpoints_c: list[float], seed: int = 3) -> list[SoakTrace]:
    """Each setpoint's ramp (the air polled from the write until within 1 °C) and a soak of 90 min after it,
    as a campaign keeps them, from the thermal model with TRUE's constants and noise on every reading."""
    rng = np.random.default_rng(seed)
    model = ThermalModel(TRUE["room_c"], TRUE["heating_c_per_min"] / 60.0, TRUE["air_tau_min"] * 60.0,
                         [tau * 60.0 for tau in TRUE["dut_tau_min"]], 0.0, overshoot_fraction=TRUE["overshoot"],
                         cooling_floor_c=TRUE["floor_c"], cooling_rate_c_per_s=TRUE["cooling_c_per_min"] / 60.0)
    found, t = [], 0.0
    for setpoint_c in setpoints_c:
        model.set_setpoint(t, setpoint_c)
        ramp_t, ramp_c = [], []
        while True:
            air = model.air_c(t) + rng.normal(0.0, NOISE_C)
            ramp_t.append(t)
            ramp_c.append(air)
            if abs(air - setpoint_c) <= 1.0:
                break
            t += POLL_S
        reached = t
        soak_t = reached + POLL_S * np.arange(1, 541)
        truth = [(model.air_c(s), model.duts_c(s)) for s in soak_t]  # the model only moves forward in time
        air = np.array([a for a, _ in truth]) + rng.normal(0.0, NOISE_C, len(soak_t))
        duts = np.array([d for _, d in truth]) + rng.normal(0.0, NOISE_C, (len(soak_t), 2))
        found.append(SoakTrace(f"T{setpoint_c:g}", setpoint_c, "stable", soak_t, air, duts, reached, soak_t[-1],
                               duts[-1], ramp_t_s=np.array(ramp_t), ramp_chamber_c=np.array(ramp_c)))
        t = soak_t[-1] + POLL_S
    return found


def test_the_constants_the_traces_were_made_with_are_recovered() -> None:
    fitted = fit_thermal_constants(traces([-40.0, -10.0, 20.0, 50.0, 0.0, -60.0]), ["A", "B"])
    chamber = fitted.chamber
    assert chamber.heating_rate_c_per_min == pytest.approx(TRUE["heating_c_per_min"], rel=0.03)
    assert chamber.cooling_rate_c_per_min == pytest.approx(TRUE["cooling_c_per_min"], rel=0.05)
    assert chamber.cooling_floor_c == pytest.approx(TRUE["floor_c"], abs=5.0)
    assert chamber.chamber_time_constant_min == pytest.approx(TRUE["air_tau_min"], rel=0.05)
    assert chamber.chamber_overshoot_pct == pytest.approx(100 * TRUE["overshoot"], abs=0.5)
    assert chamber.residual_rms_c == pytest.approx(NOISE_C, rel=0.3)  # the noise, not less: nothing over-fitted
    assert [d.time_constant_min for d in fitted.duts] == pytest.approx(list(TRUE["dut_tau_min"]), rel=0.03)
    assert fitted.fixture_time_constant_min == pytest.approx(max(TRUE["dut_tau_min"]), rel=0.03)


def test_a_chamber_that_never_cools_far_has_no_floor_and_heating_only_no_cooling_rate() -> None:
    fitted = fit_thermal_constants(traces([30.0, 45.0, 60.0]), ["A", "B"])
    assert fitted.chamber.cooling_rate_c_per_min is None and fitted.chamber.cooling_floor_c is None
    assert fitted.chamber.heating_rate_c_per_min == pytest.approx(TRUE["heating_c_per_min"], rel=0.03)


def test_soaks_without_their_ramps_cannot_be_fitted() -> None:
    kept = traces([30.0])
    without = [SoakTrace(s.label, s.setpoint_c, s.outcome, s.t_s, s.chamber_c, s.dut_c, s.t_reached_s, s.t_stable_s,
                         s.settled_dut_c) for s in kept]
    with pytest.raises(ValueError, match="no ramp kept with any soak"):
        fit_thermal_constants(without, ["A", "B"])
