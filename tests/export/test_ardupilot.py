"""`rig export --format ardupilot-params`: read back as ArduPilot reads a .param file and applied as its
IMU temperature calibration applies INS_TCAL<n>_, together with its own accelerometer offsets, the
correction is the bias `apply` removes."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import DutCalibration, load_calibration, save_calibration
from tests.export.stack_support import G0, bias_removed_m_s2, export, stated, written_comments

REFERENCE_C = 35.0  # ArduPilot's TEMP_REFERENCE
SCALE = 1e6  # ArduPilot's SCALE_FACTOR: the parameters are the coefficients times this


def read_ardupilot_params(path: Path) -> dict[str, float]:
    """As AP_Param::parse_param_line reads a line: '#' starts a comment, name and value are separated by any
    of ", =\\t"; names are at most 16 characters (AP_MAX_NAME_SIZE)."""
    values = {}
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            continue
        name, value = re.split(r"[, =\t]+", line.strip())
        assert len(name) <= 16, name
        values[name] = float(value)
    return values


def tcal_polynomial_m_s2(params: dict[str, float], n: int, temperature_c: np.ndarray) -> np.ndarray:
    """TCal::polynomial_eval of the clipped temperature: (ACC1·u + ACC2·u² + ACC3·u³)·1e-6, u = T - 35 °C."""
    p = f"INS_TCAL{n}_"
    u = np.clip(temperature_c, params[p + "TMIN"], params[p + "TMAX"]) - REFERENCE_C
    return np.stack([sum(params[f"{p}ACC{k}_{axis}"] * u**k for k in (1, 2, 3)) / SCALE for axis in "XYZ"], axis=-1)


def ardupilot_corrected_m_s2(params: dict[str, float], n: int, raw_m_s2: np.ndarray, temperature_c: np.ndarray,
                             cal_temp_c: float, accel_offset_m_s2: np.ndarray) -> np.ndarray:
    """_rotate_and_correct_accel in the sensor frame with INS_ACCSCAL 1: TCal::correct_sensor subtracts
    P(T) - P(T_cal) (both clipped), then INS_ACCOFFS is subtracted."""
    tcal = tcal_polynomial_m_s2(params, n, temperature_c) - tcal_polynomial_m_s2(params, n, np.array([cal_temp_c]))
    return raw_m_s2 - tcal - accel_offset_m_s2


def rounding_bound_m_s2(params: dict[str, float], n: int, temperatures: list[np.ndarray]) -> np.ndarray:
    """Every coefficient is written with 9 significant digits (≤ 5e-9 of itself); re-expanding about 35 °C in
    float64 rounds at ~1e-16 of each term: 1e-8 of Σ_k |ACC_k|·|u|^k·1e-6 per polynomial evaluated covers both."""
    p = f"INS_TCAL{n}_"
    total = 0.0
    for temperature_c in temperatures:
        u = np.abs(np.clip(temperature_c, params[p + "TMIN"], params[p + "TMAX"]) - REFERENCE_C)
        total = total + np.stack([sum(abs(params[f"{p}ACC{k}_{a}"]) * u**k for k in (1, 2, 3)) for a in "XYZ"], -1)
    return total / SCALE * 1e-8


def ardupilot_export(capsys, calibration: Path, folder: Path, *options: str) -> tuple[Path, list[str]]:
    out = folder / "tcal.param"
    code, stdout, notes = export(capsys, [str(calibration), "--format", "ardupilot-params", *options, "-o", str(out)])
    assert code == 0 and stdout.startswith("ardupilot-params of sensor ")
    return out, notes


@pytest.mark.parametrize("cal_temp_c", [22.0, REFERENCE_C, -60.0])  # -60: below TMIN, clipped as ArduPilot clips
def test_with_ardupilots_own_offsets_the_correction_is_the_bias_apply_removes(fitted_paper_campaign, tmp_path,
                                                                              capsys, cal_temp_c: float) -> None:
    calibration_path = fitted_paper_campaign[1]
    calibration = load_calibration(calibration_path)
    rng = np.random.default_rng(11)
    for serial, sensor in calibration.of_quantity("acceleration").items():
        params = read_ardupilot_params(ardupilot_export(capsys, calibration_path, tmp_path, "--serial", serial)[0])
        assert params["INS_TCAL1_ENABLE"] == 1
        low, high = sensor.validity_c
        # ArduPilot's accelerometer calibration runs with the temperature calibration off (the correction is
        # skipped while it runs), so its INS_ACCOFFS is the raw offset at T_cal: the bias there.
        cal_at = np.clip(cal_temp_c, low, high)
        accel_offset = -bias_removed_m_s2(sensor, np.zeros((1, 3)), np.array([cal_at]))
        temperature = np.linspace(low, high, 301)
        raw = rng.normal(0.0, G0, (temperature.size, 3))
        corrected = ardupilot_corrected_m_s2(params, 1, raw, temperature, cal_temp_c, accel_offset)
        difference = np.abs(corrected - bias_removed_m_s2(sensor, raw, temperature))
        bound = rounding_bound_m_s2(params, 1, [temperature, np.array([cal_temp_c])]) + 1e-12
        assert np.all(difference <= bound), difference.max()


def test_beyond_tmin_and_tmax_the_correction_holds_at_the_nearer_end(fitted_paper_campaign, tmp_path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    sensor = load_calibration(calibration_path).channel("ADX355-A002", "accel")
    params = read_ardupilot_params(ardupilot_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A002")[0])
    low, high = sensor.validity_c
    assert (params["INS_TCAL1_TMIN"], params["INS_TCAL1_TMAX"]) == pytest.approx((low, high), abs=1e-6)
    outside = np.array([low - 30.0, high + 25.0])
    ends = np.array([params["INS_TCAL1_TMIN"], params["INS_TCAL1_TMAX"]])
    np.testing.assert_allclose(tcal_polynomial_m_s2(params, 1, outside), tcal_polynomial_m_s2(params, 1, ends),
                               rtol=0, atol=1e-12)
    unclipped = {**params, "INS_TCAL1_TMIN": -1e9, "INS_TCAL1_TMAX": 1e9}
    assert np.max(np.abs(tcal_polynomial_m_s2(unclipped, 1, outside) - tcal_polynomial_m_s2(params, 1, ends))) > 1e-3


def test_the_file_and_stderr_state_the_offset_left_to_ardupilot_and_what_is_not_exported(fitted_paper_campaign,
                                                                                          tmp_path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    sensor = load_calibration(calibration_path).channel("ADX355-A001", "accel")
    out, notes = ardupilot_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A001")
    assert set(notes) <= written_comments(out)
    at_35 = stated(r"at 35\.00 degC it is (-?[\d.]+), (-?[\d.]+), (-?[\d.]+) mg", notes)
    bias_mg = -bias_removed_m_s2(sensor, np.zeros((1, 3)), np.array([REFERENCE_C]))[0] / G0 * 1e3
    assert at_35 == pytest.approx(bias_mg, abs=5e-4)
    assert any("INS_ACCOFFS_X/Y/Z" in note and "INS_ACC1_CALTEMP" in note for note in notes)
    scale_ppm, = stated(r"scale error up to (\d+) ppm", notes)
    left_mg, = stated(r"together up to ([\d.]+) mg at 1 g left uncorrected", notes)
    assert scale_ppm > 1000 and left_mg > 1.0


def test_a_polynomial_above_degree_3_is_refitted_and_how_far_it_strays_is_stated(fitted_paper_campaign, tmp_path,
                                                                                 capsys) -> None:
    calibration = load_calibration(fitted_paper_campaign[1])
    sensor = calibration.channel("ADX355-A001", "accel")
    coefficients = dict(sensor.polynomial.coefficients)
    coefficients["bias_x_g"] = [*coefficients["bias_x_g"], 2e-4, -1e-4]  # x⁴ and x⁵: 0.1 … 0.3 mg at the ends
    quintic = sensor.model_copy(update={"polynomial": sensor.polynomial.model_copy(
        update={"degree": 5, "coefficients": coefficients})})
    path = tmp_path / "quintic.calibration.yaml"
    only = calibration.model_copy(update={"duts": {sensor.serial: DutCalibration(channels={"accel": quintic})}})
    save_calibration(only, path)
    quintic = load_calibration(path).channel(sensor.serial, "accel")
    out, notes = ardupilot_export(capsys, path, tmp_path)  # the file's only sensor: no --serial needed
    params = read_ardupilot_params(out)
    refit_mg, = stated(r"degree-5 bias polynomial refitted as ArduPilot's cubic: up to ([\d.]+) mg", notes)
    low, high = quintic.validity_c
    temperature = np.linspace(low, high, 2001)
    accel_offset = -bias_removed_m_s2(quintic, np.zeros((1, 3)), np.array([REFERENCE_C]))
    corrected = ardupilot_corrected_m_s2(params, 1, np.zeros((temperature.size, 3)), temperature, REFERENCE_C,
                                         accel_offset)
    strays_mg = np.max(np.abs(corrected - bias_removed_m_s2(quintic, np.zeros((temperature.size, 3)), temperature)),
                       axis=0) / G0 * 1e3
    # Only x has terms above the cubic; at T_cal = 35 °C the offset is exact, so x may stray by up to twice the
    # cubic's own largest error (there and at T), and the stated figure is the cubic's own error.
    assert 0.0 < refit_mg and strays_mg[0] <= 2 * refit_mg + 1e-4 and strays_mg[0] >= 0.5 * refit_mg
    assert np.all(strays_mg[1:] < 1e-6)


def test_instance_names_the_imu_and_device_id_is_refused(fitted_paper_campaign, tmp_path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    out, notes = ardupilot_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A003", "--instance", "3")
    params = read_ardupilot_params(out)
    assert len(params) == 3 + 9 and all(name.startswith("INS_TCAL3_") for name in params)
    assert any("INS_ACC3OFFS_X/Y/Z" in note and "INS_ACC3_CALTEMP" in note for note in notes)
    for bad, expected in ((["--instance", "0"], "--instance 0:"), (["--device-id", "7"], "--device-id is PX4's")):
        assert main(["export", str(calibration_path), "--format", "ardupilot-params", "--serial", "ADX355-A003",
                     *bad]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and expected in err, err
