"""The calibration file: written, read back, checked on load, and applied to readings."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import CalibrationRangeWarning, apply, apply_codes, load_calibration, save_calibration
from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.fit.sfem import correct, distort
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.plan import schedules
from accelcal_rig.sim.truth import truth_for_serial

#: A calibration of format version 2 as the previous version wrote it (an IMU's accelerometer and gyroscope).
VERSION_2 = Path(__file__).parents[1] / "data" / "calibration-v2" / "imu-one-dut.calibration.yaml"


@pytest.fixture(scope="module")
def calibration(paper_campaign):
    from accelcal_rig.store.read import load_campaign

    calibration, _ = fit_campaign(load_campaign(paper_campaign), FitOptions(), {"campaign": str(paper_campaign)})
    return calibration


def test_round_trip_through_yaml(calibration, tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    save_calibration(calibration, path)
    loaded = load_calibration(path)
    assert loaded == calibration
    sensor = loaded.channel("ADX355-A001", "accel")
    np.testing.assert_array_equal(sensor.parameters_at(np.array([0.0, 25.0])),
                                  calibration.channel("ADX355-A001", "accel").parameters_at(np.array([0.0, 25.0])))


def test_apply_undoes_the_simulated_sensor_at_any_temperature(calibration) -> None:
    serial = "ADX355-A002"
    truth = truth_for_serial(serial)
    directions = schedules.sphere(200)
    temperatures = np.random.default_rng(0).uniform(-35, 55, 200)
    raw = distort(directions, truth.parameters_at(temperatures))
    compensated = apply(calibration.channel(serial, "accel"), raw, temperatures)
    # reference mode recovers the full vector, not only its norm; the fit's noise is ~10 µg
    assert np.abs(compensated - directions).max() < 1e-4
    np.testing.assert_allclose(np.linalg.norm(compensated, axis=1), 1.0, atol=5e-5)
    codes = ADXL355.channel("accel").quantise(raw, 2)
    np.testing.assert_allclose(apply_codes(calibration.channel(serial, "accel"), codes, temperatures), compensated, atol=1e-5)


def test_outside_the_calibrated_range_it_clamps_and_says_so(calibration) -> None:
    sensor = calibration.channel("ADX355-A001", "accel")
    with pytest.warns(CalibrationRangeWarning, match="2 of 3 temperatures clamped"):
        clamped = sensor.parameters_at(np.array([-60.0, 0.0, 90.0]))
    low, high = sensor.validity_c
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # inside the range: silent
        np.testing.assert_allclose(clamped[[0, 2]], sensor.parameters_at(np.array([low, high])))


def test_extrapolation_when_the_file_asks_for_it(calibration) -> None:
    sensor = calibration.channel("ADX355-A001", "accel").model_copy(update={"out_of_range": "extrapolate"})
    with pytest.warns(CalibrationRangeWarning, match="extrapolated beyond"):
        beyond = sensor.parameters_at(90.0)
    assert not np.allclose(beyond, sensor.parameters_at(sensor.validity_c[1]))


def test_a_file_of_another_version_is_refused_with_its_line(calibration, tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    save_calibration(calibration, path)
    data = yaml.safe_load(path.read_text())
    data["format_version"] = 4
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(ConfigError, match=r"cal.yaml:\d+: format_version: calibration format version 4 is not supported"):
        load_calibration(path)


def test_a_version_2_file_reads_as_version_3_value_for_value() -> None:
    """A file the previous version wrote (each quantity's entry its own shape): every channel the one shape, its
    range and code size by name, every figure and coefficient as written, and it applies as it did."""
    raw = yaml.safe_load(VERSION_2.read_text())
    read = load_calibration(VERSION_2)
    accel = read.channel("IMU-A001", "accel")
    written = raw["duts"]["IMU-A001"]["channels"]["accel"]
    assert (accel.quantity, accel.unit, accel.model) == ("acceleration", "g", "sfem-eq1")
    assert (accel.range, accel.lsb) == (written["range_g"], written["lsb_g"])
    assert accel.polynomial.coefficients == written["polynomial"]["coefficients"]
    assert accel.metrics == written["metrics"] and accel.decision == written["decision"]
    expected = correct(np.array([[0.01, -0.99, 0.02]]), accel.polynomial.at(21.0))
    np.testing.assert_array_equal(apply(accel, np.array([[0.01, -0.99, 0.02]]), 21.0), expected)
    gyro, written = read.channel("IMU-A001", "gyro"), raw["duts"]["IMU-A001"]["channels"]["gyro"]
    assert (gyro.quantity, gyro.unit, gyro.model, gyro.mode) == ("angular rate", "dps", "gyro-rate-table", "rate-table")
    assert (gyro.range, gyro.lsb) == (written["range_dps"], written["lsb_dps"])
    assert gyro.statements == {"earth_rate": written["earth_rate"], "gauge": written["gauge"]}
    assert gyro.polynomial.coefficients == written["polynomial"]["coefficients"] and gyro.verdict == written["verdict"]
    rate = apply(gyro, np.array([[100.0, 0.5, -0.2]]), 21.0, {"acceleration": np.array([[0.0, 0.0, 1.0]])})
    assert abs(rate[0, 0] - 100.0) < 1.0


def test_a_version_1_file_reads_as_each_duts_acceleration_channel(tmp_path: Path) -> None:
    """Version 1 (before channels): `sensors` by serial, every one an accelerometer."""
    data = yaml.safe_load(VERSION_2.read_text())
    path = tmp_path / "cal.yaml"
    version_1 = {**{k: v for k, v in data.items() if k != "duts"}, "format_version": 1,
                 "sensors": {serial: dut["channels"]["accel"] for serial, dut in data["duts"].items()}}
    path.write_text(yaml.safe_dump(version_1, sort_keys=False))
    read = load_calibration(path)
    assert read.channel("IMU-A001", "accel") == load_calibration(VERSION_2).channel("IMU-A001", "accel")
    assert list(read.duts["IMU-A001"].channels) == ["accel"]
    assert read.not_calibrated() == {}


def test_a_channel_no_model_calibrates_is_named_with_why(calibration) -> None:
    dut = calibration.duts["ADX355-A001"].model_copy(update={"not_calibrated": {"gyro": "angular rate: no model yet"}})
    with_gyro = calibration.model_copy(update={"duts": {**calibration.duts, "ADX355-A001": dut}})
    with pytest.raises(KeyError, match=r"ADX355-A001: no calibration of its gyro channel \(angular rate: no model yet\)"):
        with_gyro.channel("ADX355-A001", "gyro")
    assert with_gyro.not_calibrated() == {"ADX355-A001": {"gyro": "angular rate: no model yet"}}


def test_unknown_sensor_is_named(calibration) -> None:
    with pytest.raises(KeyError, match="no calibration for sensor SN-X"):
        calibration.channel("SN-X", "accel")


def test_the_documented_usage_snippet_runs(calibration, tmp_path: Path) -> None:
    import re
    import subprocess
    import sys

    from tests.conftest import REPO

    save_calibration(calibration, tmp_path / "calibration.yaml")
    doc = (REPO / "docs" / "calibration.md").read_text()
    snippet = re.search(r"```python\n(.*?)```", doc, re.S).group(1)
    result = subprocess.run([sys.executable, "-c", snippet + "\nprint(compensated_g.shape, compensated_from_codes.shape)"],
                            cwd=tmp_path, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "(2, 3) (1, 3)"


def test_a_problem_in_a_version_1_file_is_reported_at_its_own_key_and_line(tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    data = yaml.safe_load(VERSION_2.read_text())
    sensors = {serial: dut["channels"]["accel"] for serial, dut in data["duts"].items()}
    sensors["IMU-A001"]["range_g"] = -2
    version_1 = {**{k: v for k, v in data.items() if k != "duts"}, "format_version": 1, "sensors": sensors}
    path.write_text(yaml.safe_dump(version_1, sort_keys=False))
    line = path.read_text().splitlines().index("  IMU-A001:") + 1
    with pytest.raises(ConfigError, match=r"cal.yaml:\d+: sensors.IMU-A001.range_g: Input should be greater than 0"):
        load_calibration(path)
    assert line > 0
