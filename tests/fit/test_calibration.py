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
from accelcal_rig.fit.sfem import distort
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.plan import schedules
from accelcal_rig.sim.truth import truth_for_serial


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
    sensor = loaded.sensor("ADX355-A001")
    np.testing.assert_array_equal(sensor.parameters_at(np.array([0.0, 25.0])),
                                  calibration.sensor("ADX355-A001").parameters_at(np.array([0.0, 25.0])))


def test_apply_undoes_the_simulated_sensor_at_any_temperature(calibration) -> None:
    serial = "ADX355-A002"
    truth = truth_for_serial(serial)
    directions = schedules.sphere(200)
    temperatures = np.random.default_rng(0).uniform(-35, 55, 200)
    raw = distort(directions, truth.parameters_at(temperatures))
    compensated = apply(calibration.sensor(serial), raw, temperatures)
    # reference mode recovers the full vector, not only its norm; the fit's noise is ~10 µg
    assert np.abs(compensated - directions).max() < 1e-4
    np.testing.assert_allclose(np.linalg.norm(compensated, axis=1), 1.0, atol=5e-5)
    codes = ADXL355.channel("accel").quantise(raw, 2)
    np.testing.assert_allclose(apply_codes(calibration.sensor(serial), codes, temperatures), compensated, atol=1e-5)


def test_outside_the_calibrated_range_it_clamps_and_says_so(calibration) -> None:
    sensor = calibration.sensor("ADX355-A001")
    with pytest.warns(CalibrationRangeWarning, match="2 of 3 temperatures clamped"):
        clamped = sensor.parameters_at(np.array([-60.0, 0.0, 90.0]))
    low, high = sensor.validity_c
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # inside the range: silent
        np.testing.assert_allclose(clamped[[0, 2]], sensor.parameters_at(np.array([low, high])))


def test_extrapolation_when_the_file_asks_for_it(calibration) -> None:
    sensor = calibration.sensor("ADX355-A001").model_copy(update={"out_of_range": "extrapolate"})
    with pytest.warns(CalibrationRangeWarning, match="extrapolated beyond"):
        beyond = sensor.parameters_at(90.0)
    assert not np.allclose(beyond, sensor.parameters_at(sensor.validity_c[1]))


def test_a_file_of_another_version_is_refused_with_its_line(calibration, tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    save_calibration(calibration, path)
    data = yaml.safe_load(path.read_text())
    data["format_version"] = 3
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(ConfigError, match=r"cal.yaml:\d+: format_version: calibration format version 3 is not supported"):
        load_calibration(path)


def test_a_version_1_file_reads_as_each_duts_acceleration_channel(calibration, tmp_path: Path) -> None:
    """Version 1 (before channels): `sensors` by serial, every one an accelerometer."""
    path = tmp_path / "cal.yaml"
    save_calibration(calibration, path)
    data = yaml.safe_load(path.read_text())
    assert data["format_version"] == 2 and set(data["duts"]["ADX355-A001"]["channels"]) == {"accel"}
    version_1 = {**{k: v for k, v in data.items() if k != "duts"}, "format_version": 1,
                 "sensors": {serial: dut["channels"]["accel"] for serial, dut in data["duts"].items()}}
    path.write_text(yaml.safe_dump(version_1, sort_keys=False))
    read = load_calibration(path)
    assert read.sensors == calibration.sensors and read.sensor("ADX355-A001") == calibration.sensor("ADX355-A001")
    assert read.not_calibrated() == {}


def test_a_channel_no_model_calibrates_is_named_with_why(calibration) -> None:
    dut = calibration.duts["ADX355-A001"].model_copy(update={"not_calibrated": {"gyro": "angular rate: no model yet"}})
    with_gyro = calibration.model_copy(update={"duts": {**calibration.duts, "ADX355-A001": dut}})
    with pytest.raises(KeyError, match=r"ADX355-A001: no calibration of its gyro channel \(angular rate: no model yet\)"):
        with_gyro.gyroscope("ADX355-A001")
    assert with_gyro.not_calibrated() == {"ADX355-A001": {"gyro": "angular rate: no model yet"}}


def test_unknown_sensor_is_named(calibration) -> None:
    with pytest.raises(KeyError, match="no calibration for sensor SN-X"):
        calibration.sensor("SN-X")


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


def test_a_problem_in_a_version_1_file_is_reported_at_its_own_key_and_line(calibration, tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    save_calibration(calibration, path)
    data = yaml.safe_load(path.read_text())
    sensors = {serial: dut["channels"]["accel"] for serial, dut in data["duts"].items()}
    del sensors["ADX355-A002"]["lsb_g"]
    version_1 = {**{k: v for k, v in data.items() if k != "duts"}, "format_version": 1, "sensors": sensors}
    path.write_text(yaml.safe_dump(version_1, sort_keys=False))
    line = path.read_text().splitlines().index("  ADX355-A002:") + 1
    with pytest.raises(ConfigError, match=rf"cal.yaml:{line}: sensors.ADX355-A002.lsb_g: Field required"):
        load_calibration(path)
