import numpy as np
import pytest

from accelcal_rig.config.load import load_procedure, load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.fit.sfem import distort
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.sim.devices import build_simulated_rig
from tests.conftest import REPO, SIM_RIG


@pytest.fixture
def rig():
    clock = VirtualClock()
    procedure = load_procedure(REPO / "procedures" / "quick-6pos.yaml").model
    return clock, build_simulated_rig(load_rig(SIM_RIG).model, procedure, clock, seed=7)


def test_block_mean_matches_the_truth_within_the_noise(rig) -> None:
    clock, instruments = rig
    sensor = instruments.sensors[1]
    sensor.configure({"accel": 2}, 125.0)
    sensor.start_measurement()
    block = sensor.acquire(2000)
    assert block.codes["accel"].shape == (2000, 3) and block.codes["accel"].dtype == np.int32
    truth = instruments.truth.block_truth(sensor.serial, block)
    expected = distort(truth["gravity_g"], truth["parameters"])
    lsb = ADXL355.channel("accel").lsb(2)
    measured = block.codes["accel"] * lsb
    noise = sensor.noise_g()
    np.testing.assert_allclose(measured.mean(axis=0), expected, atol=5 * noise / np.sqrt(2000))
    np.testing.assert_allclose(measured.std(axis=0), noise, rtol=0.1)


def test_noise_follows_the_datasheet_density_and_data_rate(rig) -> None:
    _, instruments = rig
    sensor = instruments.sensors[0]
    sensor.configure({"accel": 2}, 125.0)
    slow = sensor.noise_g()
    sensor.configure({"accel": 2}, 4000.0)
    assert sensor.noise_g() == pytest.approx(slow * np.sqrt(32))
    assert 0.15e-3 < slow < 0.25e-3  # 25 µg/√Hz over a 31 Hz corner


def test_acquire_takes_its_time_on_the_clock(rig) -> None:
    clock, instruments = rig
    sensor = instruments.sensors[0]
    sensor.start_measurement()
    block = sensor.acquire(250)
    assert clock.now() == pytest.approx(2.0)
    assert block.t_end_s - block.t_start_s == pytest.approx(249 / 125)


def test_standby_rules_of_the_part(rig) -> None:
    _, instruments = rig
    sensor = instruments.sensors[0]
    with pytest.raises(InstrumentError, match="standby"):
        sensor.acquire(10)
    sensor.start_measurement()
    with pytest.raises(InstrumentError, match="only change in standby"):
        sensor.configure({"accel": 4}, 125.0)


def test_turntable_moves_at_its_speed_then_settles(rig) -> None:
    clock, instruments = rig
    table = instruments.turntable
    table.move_to(np.array([0.0, 90.0, 0.0]))  # 90° at 20°/s: 4.5 s, then 0.5 s settle
    clock.sleep(2.0)
    assert not table.in_position()
    assert table.read_angles_deg()[1] == pytest.approx(40.0, abs=0.01)
    clock.sleep(3.1)
    assert table.in_position()
    assert table.read_angles_deg()[1] == pytest.approx(90.0, abs=3 / 3600 + 1e-12)


def test_turntable_stop_holds_the_current_angle(rig) -> None:
    clock, instruments = rig
    table = instruments.turntable
    table.move_to(np.array([0.0, 90.0, 0.0]))
    clock.sleep(1.0)
    table.stop()
    clock.sleep(10.0)
    assert table.read_angles_deg()[1] == pytest.approx(20.0, abs=0.01)


def test_temperature_reading_is_quantised_like_the_adxl355(rig) -> None:
    _, instruments = rig
    readings = {instruments.sensors[0].read_temperature_c() for _ in range(50)}
    raws = [(25 - t) * 9.05 + 1885 for t in readings]
    np.testing.assert_allclose(raws, np.round(raws), atol=1e-9)


def test_unmodelled_effects_are_off_unless_the_procedure_asks() -> None:
    from accelcal_rig.config.procedure import SimulatedEffects
    from accelcal_rig.sim.lab import VirtualLab

    rig = load_rig(SIM_RIG).model
    gravity = np.array([0.0, 0.6, 0.8])
    plain = VirtualLab(rig, VirtualClock(), 0)
    np.testing.assert_array_equal(plain.unmodelled_g(0, gravity), 0.0)
    lab = VirtualLab(rig, VirtualClock(), 0, SimulatedEffects(hysteresis_mg=1.0, nonlinearity_mg_per_g2=0.5))
    effect = lab.unmodelled_g(0, gravity)
    np.testing.assert_allclose(np.abs(effect - lab.unmodelled_g(0, np.zeros(3))), 0.5e-3 * gravity**2)
    warm = lab.unmodelled_g(0, np.zeros(3))
    lab.thermal.set_setpoint(0.0, -20.0)   # cooling: the sensor now approaches from above
    lab.clock.sleep(600.0)
    lab.dut_true_c(0)
    np.testing.assert_allclose(lab.unmodelled_g(0, np.zeros(3)), -warm)
    assert np.allclose(np.abs(warm), 0.5e-3)


def test_every_dut_sampled_at_one_instant_follows_its_own_truth_there() -> None:
    from accelcal_rig.sim.lab import VirtualLab

    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 3)
    lab.thermal.set_setpoint(0.0, 50.0)
    for t_s in (900.0, 1800.0):   # the fixture's state is evaluated afresh at each instant
        lab.clock.sleep(t_s - lab.clock.now())
        for index, dut in enumerate(lab.duts):
            lab.dut_samples(index, t_s, 10, 125.0, 2)
            _, _, _, parameters, gravity_g, temperature_c = dut.truth_log[-1]
            assert temperature_c == lab.dut_true_c(index)
            np.testing.assert_allclose(parameters, dut.truth.parameters_at(temperature_c), atol=1e-15)
            np.testing.assert_allclose(gravity_g, lab.gravity_in_dut(index), atol=1e-15)
    assert len({log.truth_log[-1][5] for log in lab.duts}) > 1   # DUTs lag differently: different truths
