import numpy as np
import pytest

from accelcal_rig.core.thermal import ThermalModel


def model(**overrides) -> ThermalModel:
    settings = dict(ambient_c=23.0, ramp_rate_c_per_s=3 / 60, chamber_tau_s=180.0, dut_tau_s=[600.0, 900.0],
                    self_heating_c=0.2)
    settings.update(overrides)
    return ThermalModel(**settings)


def test_starts_at_ambient_with_self_heating() -> None:
    m = model()
    assert m.air_c(0.0) == 23.0
    assert m.dut_c(0.0, 0) == 23.2


def test_air_change_is_limited_by_the_ramp_rate() -> None:
    m = model()
    m.set_setpoint(0.0, -40.0)
    times = np.arange(0.0, 1200.0, 10.0)
    air = np.array([m.air_c(t) for t in times])
    assert np.all(np.diff(air) <= 0)  # monotonic, no overshoot
    assert np.all(np.abs(np.diff(air)) / 10.0 <= 3 / 60 + 1e-9)


def test_settles_at_setpoint_and_duts_lag_the_air_by_their_time_constants() -> None:
    m = model()
    m.set_setpoint(0.0, 60.0)
    t_ramp_end = 37 / (3 / 60)
    assert m.dut_c(t_ramp_end, 1) < m.dut_c(t_ramp_end, 0) < m.air_c(t_ramp_end)  # slower DUT lags more
    assert abs(m.air_c(t_ramp_end + 3600) - 60.0) < 1e-3
    assert abs(m.dut_c(t_ramp_end + 3 * 3600, 1) - 60.2) < 1e-3


def test_query_granularity_does_not_change_the_answer() -> None:
    coarse, fine = model(), model()
    coarse.set_setpoint(0.0, -20.0)
    fine.set_setpoint(0.0, -20.0)
    for t in np.arange(0.0, 2000.0, 1.0):
        fine.dut_c(t, 0)
    assert abs(coarse.dut_c(2000.0, 0) - fine.dut_c(2000.0, 0)) < 0.01


def test_advancing_is_bounded_whatever_the_gaps() -> None:
    """Setpoints a hair from the reference, and queries a hair apart, each cost one sub-step at most."""
    from accelcal_rig.core import thermal

    m = model()
    steps = []
    real_step = m._step
    m._step = lambda step_s, rate, arrives: (steps.append(step_s), real_step(step_s, rate, arrives))  # type: ignore[method-assign]
    for k in range(1, 200):
        m.set_setpoint(k * 1e-3, 23.0 + (-1) ** k * 1e-13)
        m.air_c(k * 1e-3 + 1e-12)
    assert len(steps) <= 2 * 2 * 200
    m.air_c(1e6)
    assert len(steps) <= 2 * 2 * 200 + 1e6 / thermal.MAX_STEP_S + 2


def test_the_air_overshoots_a_step_by_about_its_share_after_the_ramp_arrives_then_settles() -> None:
    m = model(overshoot_fraction=0.05)
    m.set_setpoint(0.0, 43.0)  # a 20 °C step: the controller drives 1 °C past it once the ramp arrives (400 s)
    times = np.arange(0.0, 6000.0, 5.0)
    air = np.array([m.air_c(t) for t in times])
    peak = int(np.argmax(air))
    assert 43.6 < air[peak] < 44.1
    assert 400.0 < times[peak] < 1600.0
    assert abs(air[-1] - 43.0) < 0.1  # and settles back


def test_cooling_slows_towards_the_compressors_floor_and_heating_does_not() -> None:
    m = model(cooling_floor_c=-75.0)
    assert m.ramp_rate_at_c_per_s(23.0, cooling=True) == 3 / 60
    assert m.ramp_rate_at_c_per_s(-40.0, cooling=True) == pytest.approx(3 / 60 * 35 / 98)
    assert m.ramp_rate_at_c_per_s(-40.0, cooling=False) == 3 / 60
    m.set_setpoint(0.0, -40.0)
    plain = model()
    plain.set_setpoint(0.0, -40.0)
    assert m.air_c(1260.0) > plain.air_c(1260.0) + 5.0  # 21 min: the plain chamber is there, this one is not


def test_slots_further_from_the_inlet_sit_nearer_ambient() -> None:
    m = model(slot_offset_per_c=[0.0, -1.0 / 60.0])
    m.set_setpoint(0.0, 83.0)
    m.air_c(20000.0)
    first, last = m.dut_c(20000.0, 0), m.dut_c(20000.0, 1)
    assert first - last == pytest.approx(1.0, abs=0.01)  # 60 °C above ambient: 1 °C apart


def test_hysteresis_swings_over_its_span_and_relaxes() -> None:
    m = model(hysteresis_span_c=10.0, hysteresis_time_constant_s=3600.0)
    m.set_setpoint(0.0, 13.0)  # cooling 10 °C: the state swings from +1 towards −1
    m.air_c(7200.0)
    assert np.all(m.hysteresis_state < 0) and np.all(m.hysteresis_state > -1)
    settled = m.hysteresis_state.copy()
    m.air_c(7200.0 + 3 * 3600.0)  # held: it relaxes towards none with its time constant
    np.testing.assert_allclose(m.hysteresis_state, settled * np.exp(-3.0), rtol=0.05)
