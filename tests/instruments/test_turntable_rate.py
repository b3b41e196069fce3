"""Constant-rate rotation (a rate table): the line commands byte for byte, the driver over the simulated
controller on a pty, the capability's truth through the wrappers, and the limits' refusals."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.rig import RigConfig, TurntableAxis, TurntableConfig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import ConstantRateRotation, Reconnecting
from accelcal_rig.instruments.limits import LimitedTurntable
from accelcal_rig.instruments.retrying import RetryingTurntable
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.turntable_line import ACCELCAL_LINE, turntable_protocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG
from tests.instruments.expected_protocol import expected_protocol

ACUTROL = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0})
RATE_AXIS = {"max_rate_dps": 1000.0, "max_acceleration_dps2": 500.0}


def rate_rig(accuracy_pct: float = 0.01, stability_pct: float = 0.001) -> RigConfig:
    """The simulated rig with rate limits on every axis and a stated rate accuracy and stability."""
    data = load_rig(SIM_RIG).model.model_dump(mode="json")
    data["turntable"]["axes"] = [{**axis, **RATE_AXIS} for axis in data["turntable"]["axes"]]
    data["turntable"] |= {"rate_accuracy_pct": accuracy_pct, "rate_stability_pct": stability_pct}
    return RigConfig.model_validate(data)


# ---------------------------------------------------------------------- bytes

def test_accelcal_line_rate_commands_byte_for_byte() -> None:
    with expected_protocol([(b"RATE 2 -100.00000 50.00000\n", b"OK\n"), (b"RATE? 2\n", b"-99.998700\n"),
                            (b"HOLD 2\n", b"OK\n"), (b"RATE? 2\n", b"0.000000\n")]) as line:
        table = SerialTurntable(line, "memory", ACCELCAL_LINE, 3)
        assert isinstance(table, ConstantRateRotation)
        table.rotate_at(1, -100.0, 50.0)
        assert table.read_rate_deg_s(1) == -99.9987
        table.hold(1)
        assert table.read_rate_deg_s(1) == 0.0


def test_acutrol_rate_mode_sets_limits_demand_and_mode_after_the_setup_byte_for_byte() -> None:
    setup = [(b":interlock:close 1\n", None), (b":interlock:close 2\n", None),
             (b":mode:position 1\n", None), (b":mode:position 2\n", None)]
    rotate = (b":limit:rate R,1,100.00000;:limit:acceleration R,1,20.00000;:demand:rate 1,100.00000;"
              b":mode:rate 1\n", None)
    faster = (b":limit:rate R,1,200.00000;:limit:acceleration R,1,20.00000;:demand:rate 1,-200.00000;"
              b":mode:rate 1\n", None)
    with expected_protocol([*setup, rotate, (b":read:rate? 1\n", b"100.00210\n"), faster,
                            (b":demand:rate 1,0\n", None),
                            *setup, (b":demand:position 1,0.00000;:demand:position 2,0.00000\n", None)]) as line:
        table = SerialTurntable(line, "memory", ACUTROL, 2)
        assert isinstance(table, ConstantRateRotation)
        table.rotate_at(0, 100.0, 20.0)
        assert table.read_rate_deg_s(0) == pytest.approx(100.0021)
        table.rotate_at(0, -200.0, 20.0)  # already in rate mode: no setup (no position mode while turning)
        table.hold(0)
        table.move_to(np.array([0.0, 0.0]))  # back to position mode: the setup again


def test_an_axis_the_table_does_not_have_is_refused_before_the_wire() -> None:
    with expected_protocol([]) as line:
        with pytest.raises(InstrumentError, match=r"turntable \(memory\): no axis 3 \(it has 3\)"):
            SerialTurntable(line, "memory", ACCELCAL_LINE, 3).rotate_at(3, 10.0, 10.0)


def test_a_profile_needs_rotate_and_hold_together_and_a_rate_query() -> None:
    with pytest.raises(ValueError, match="both rotate and hold"):
        turntable_protocol("accelcal-line", {"hold": None})
    with pytest.raises(ValueError, match="rate query"):
        turntable_protocol("accelcal-line", {"rate": None})


# ---------------------------------------------------------------------- over the simulated controller

@pytest.fixture
def rate_table():
    clock = VirtualClock()
    lab = VirtualLab(rate_rig(), clock, 0)
    server = SimulatedTurntableServer(lab, ACCELCAL_LINE).start()
    driver = SerialTurntable.open(server.path, ACCELCAL_LINE, n_axes=3, timeout_s=1.0)
    yield driver, lab, clock
    driver.close()
    server.stop()


def test_turns_at_100_dps_within_the_stated_accuracy_then_holds(rate_table) -> None:
    driver, lab, clock = rate_table
    assert isinstance(driver, ConstantRateRotation)
    driver.rotate_at(2, 100.0, 50.0)  # 2 s to reach 100 °/s at 50 °/s²
    clock.sleep(1.0)
    assert driver.read_rate_deg_s(2) == pytest.approx(50.0, rel=1e-3)
    assert not driver.in_position()
    clock.sleep(9.0)
    tolerance = 100.0 * (0.01 + 5 * 0.001) / 100.0  # accuracy, and five σ of the stability
    rates = [driver.read_rate_deg_s(2) for _ in range(20)]
    assert all(abs(rate - 100.0) <= tolerance for rate in rates) and len(set(rates)) > 1  # it wobbles
    angle = driver.read_angles_deg()[2]
    assert angle == pytest.approx(100.0 + 100.0 * 8.0, abs=0.2)  # the ramp's 100°, then 8 s at speed
    driver.hold(2)  # 2 s back to rest at 50 °/s²
    clock.sleep(2.6)
    assert driver.in_position() and driver.read_rate_deg_s(2) == 0.0
    still = driver.read_angles_deg()[2]
    clock.sleep(5.0)
    assert driver.read_angles_deg()[2] == still
    driver.move_to(np.array([0.0, 0.0, 30.0]))  # position mode again, the shortest way
    clock.sleep(10.0)
    assert driver.in_position()
    np.testing.assert_allclose(driver.read_angles_deg(), [0, 0, 30], atol=3 / 3600 + 1e-5)


def test_the_rate_error_is_the_rigs_own_stream() -> None:
    clock = VirtualClock()
    plain, rated = VirtualLab(load_rig(SIM_RIG).model, clock, 7), VirtualLab(rate_rig(), clock, 7)
    assert plain.rng.uniform() == rated.rng.uniform()  # existing dry runs draw the same
    assert np.all(plain.motion.rate_offsets == 0.0) and np.all(np.abs(rated.motion.rate_offsets) <= 1e-4)
    again = VirtualLab(rate_rig(), clock, 7)
    np.testing.assert_array_equal(again.motion.rate_offsets, rated.motion.rate_offsets)


# ---------------------------------------------------------------------- limits and capabilities

def config(**axis: object) -> TurntableConfig:
    return TurntableConfig(axes=[TurntableAxis.model_validate({"name": "spin", "axis": (0, 0, 1), **axis})])


def test_slip_ring_defaults_to_continuous_and_rate_limits_come_in_pairs() -> None:
    assert config(continuous=True, min_deg=-180, max_deg=180).axes[0].slip_ring
    assert not config().axes[0].slip_ring and not config().axes[0].has_rate_mode
    assert not config(continuous=True, min_deg=-180, max_deg=180, slip_ring=False).axes[0].slip_ring
    with pytest.raises(ValueError, match="both max_rate_dps and max_acceleration_dps2"):
        config(max_rate_dps=100.0)


def test_the_capability_passes_through_the_wrappers_exactly_when_the_table_has_it() -> None:
    limits = config(continuous=True, min_deg=-180, max_deg=180, **RATE_AXIS)
    for protocol, has in ((ACCELCAL_LINE, True), (turntable_protocol("accelcal-line", {"rotate": None, "hold": None}),
                                                   False)):
        with expected_protocol([]) as line:
            table = SerialTurntable(line, "memory", protocol, 1)
        for wrapper in (LimitedTurntable(table, limits), RetryingTurntable(table, lambda op, reconnect: op()),
                        LimitedTurntable(RetryingTurntable(table, lambda op, reconnect: op()), limits)):
            assert isinstance(wrapper, ConstantRateRotation) == has
            assert isinstance(wrapper, Reconnecting)


@pytest.mark.parametrize(("axis", "rate", "acceleration", "message"), [
    ({**RATE_AXIS}, 1000.5, 10.0, r"axis spin at 1000.5 °/s refused: beyond its max_rate_dps 1000 °/s"),
    ({**RATE_AXIS}, -1001.0, 10.0, r"axis spin at -1001 °/s refused: beyond its max_rate_dps"),
    ({**RATE_AXIS}, 100.0, 600.0, r"axis spin at 100 °/s refused: acceleration 600 °/s² beyond its max_acceleration_dps2 500 °/s²"),
    ({**RATE_AXIS}, 100.0, 0.0, r"axis spin at 100 °/s refused: acceleration 0 °/s² beyond its max_acceleration_dps2"),
    ({**RATE_AXIS, "slip_ring": False}, 10.0, 10.0, r"axis spin at 10 °/s refused: it has no slip ring"),
    ({}, 10.0, 10.0, r"axis spin at 10 °/s refused: the rig config gives it no rate mode \(max_rate_dps"),
])
def test_the_limits_refuse_before_anything_reaches_the_table(axis, rate, acceleration, message) -> None:
    limits = config(continuous=True, min_deg=-180, max_deg=180, **axis)
    with expected_protocol([]) as line:  # nothing may be written
        guarded = LimitedTurntable(SerialTurntable(line, "memory", ACCELCAL_LINE, 1), limits)
        assert isinstance(guarded, ConstantRateRotation)
        with pytest.raises(InstrumentError, match=rf"^turntable \(memory\): {message}"):
            guarded.rotate_at(0, rate, acceleration)


def test_a_rate_within_the_limits_goes_through() -> None:
    limits = config(continuous=True, min_deg=-180, max_deg=180, **RATE_AXIS)
    with expected_protocol([(b"RATE 1 -1000.00000 500.00000\n", b"OK\n")]) as line:
        guarded = LimitedTurntable(SerialTurntable(line, "memory", ACCELCAL_LINE, 1), limits)
        assert isinstance(guarded, ConstantRateRotation)
        guarded.rotate_at(0, -1000.0, 500.0)


def test_acutrol_rate_mode_over_its_simulator() -> None:
    clock = VirtualClock()
    lab = VirtualLab(rate_rig(), clock, 0)
    server = SimulatedTurntableServer(lab, ACUTROL).start()
    driver = SerialTurntable.open(server.path, ACUTROL, n_axes=3, timeout_s=1.0)
    try:
        assert isinstance(driver, ConstantRateRotation)
        driver.rotate_at(0, 100.0, 50.0)
        driver.read_rate_deg_s(0)  # unanswered commands are taken in order before the next request
        assert lab.motion.last_rate_command_deg_s[0] == 100.0
        clock.sleep(5.0)
        assert abs(driver.read_rate_deg_s(0) - 100.0) <= 100.0 * (0.01 + 5 * 0.001) / 100.0
        driver.hold(0)
        driver.read_rate_deg_s(0)  # the hold taken at this time
        clock.sleep(3.0)
        assert driver.read_rate_deg_s(0) == 0.0
        driver.move_to(np.array([10.0, 0.0, 0.0]))  # the setup again: position mode, then the move
        driver.read_angles_deg()
        clock.sleep(20.0)
        assert [driver.in_position() for _ in range(3)] == [False, False, True]
        np.testing.assert_allclose(driver.read_angles_deg(), [10, 0, 0], atol=3 / 3600 + 1e-5)
    finally:
        driver.close()
        server.stop()
