"""`rig export --format px4-params`: read back as QGroundControl reads a .params file and applied as PX4's
temperature_compensation module applies TC_A<n>_, the offsets are the bias `apply` removes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import CalibrationRangeWarning, load_calibration
from accelcal_rig.fit.sfem import distort
from tests.export.stack_support import G0, bias_removed_m_s2, export, stated, written_comments

INT32, REAL32 = 6, 9  # MAVLink MAV_PARAM_TYPE


def read_qgc_params(path: Path) -> dict[str, float]:
    """As QGroundControl loads a file: lines not starting with '#', five tab-separated fields (vehicle id,
    component id, name, value, type), the type checked against the parameter's."""
    values = {}
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            continue
        vehicle, component, name, value, kind = line.split("\t")
        assert (vehicle, component) == ("1", "1"), line
        integer = name.endswith(("_ENABLE", "_ID"))
        assert int(kind) == (INT32 if integer else REAL32), line
        values[name] = float(value)
    return values


def px4_offsets_m_s2(params: dict[str, float], n: int, temperature_c: np.ndarray) -> np.ndarray:
    """PX4's calc_thermal_offsets_3D, written from its documented formula: dT = T - TREF with T clipped to
    TMIN…TMAX, offset_i = X0_i + X1_i·dT + X2_i·dT² + X3_i·dT³ (m/s², axis i = 0, 1, 2 for x, y, z)."""
    p = f"TC_A{n}_"
    clipped = np.minimum(np.maximum(temperature_c, params[p + "TMIN"]), params[p + "TMAX"])
    dt = clipped - params[p + "TREF"]
    return np.stack([sum(params[f"{p}X{k}_{i}"] * dt**k for k in range(4)) for i in range(3)], axis=-1)


def rounding_bound_m_s2(params: dict[str, float], n: int, temperature_c: np.ndarray) -> np.ndarray:
    """How far the file's offsets may be from the exact re-expansion: every coefficient is written with 9
    significant digits (≤ 5e-9 of itself) and re-expanding about TREF in float64 rounds at ~1e-16 of each
    term; 1e-8 of Σ_k |X_k|·|dT|^k covers both (TREF itself is written exactly, a 0.01 °C value)."""
    p = f"TC_A{n}_"
    dt = np.abs(np.clip(temperature_c, params[p + "TMIN"], params[p + "TMAX"]) - params[p + "TREF"])
    return np.stack([sum(abs(params[f"{p}X{k}_{i}"]) * dt**k for k in range(4)) for i in range(3)], axis=-1) * 1e-8


def px4_export(capsys, calibration: Path, folder: Path, *options: str) -> tuple[Path, list[str]]:
    out = folder / "px4.params"
    code, stdout, notes = export(capsys, [str(calibration), "--format", "px4-params", *options, "-o", str(out)])
    assert code == 0 and stdout.startswith("px4-params of sensor ")
    return out, notes


def test_the_offsets_px4_subtracts_are_the_bias_apply_removes(fitted_paper_campaign, tmp_path: Path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    calibration = load_calibration(calibration_path)
    rng = np.random.default_rng(3)
    for serial, sensor in calibration.of_quantity("acceleration").items():
        out, _ = px4_export(capsys, calibration_path, tmp_path, "--serial", serial)
        params = read_qgc_params(out)
        assert params["TC_A_ENABLE"] == 1 and params["TC_A0_ID"] == 0
        low, high = sensor.validity_c
        assert params["TC_A0_TREF"] == pytest.approx(0.5 * (low + high), abs=0.005)
        temperature = np.linspace(low, high, 301)
        raw = rng.normal(0.0, G0, (temperature.size, 3))
        corrected = raw - px4_offsets_m_s2(params, 0, temperature)  # PX4: data - thermal offset (CAL_ACC off 0)
        difference = np.abs(corrected - bias_removed_m_s2(sensor, raw, temperature))
        assert np.all(difference <= rounding_bound_m_s2(params, 0, temperature) + 1e-12), difference.max()


def test_beyond_tmin_and_tmax_px4_holds_the_offset_of_the_nearer_end(fitted_paper_campaign, tmp_path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    sensor = load_calibration(calibration_path).channel("ADX355-A003", "accel")
    params = read_qgc_params(px4_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A003")[0])
    low, high = sensor.validity_c
    assert (params["TC_A0_TMIN"], params["TC_A0_TMAX"]) == pytest.approx((low, high), abs=1e-6)
    outside = np.array([low - 25.0, low - 0.5, high + 0.5, high + 30.0])
    ends = np.array([params["TC_A0_TMIN"]] * 2 + [params["TC_A0_TMAX"]] * 2)
    offsets = px4_offsets_m_s2(params, 0, outside)
    np.testing.assert_allclose(offsets, px4_offsets_m_s2(params, 0, ends), rtol=0, atol=1e-12)
    with pytest.warns(CalibrationRangeWarning):  # this calibration clamps too: the same offsets
        expected = -bias_removed_m_s2(sensor, np.zeros((4, 3)), outside)
    assert np.all(np.abs(offsets - expected) <= rounding_bound_m_s2(params, 0, outside) + 1e-12)
    # The clipping matters here: the unclipped cubic would be far off 25 °C beyond the range.
    unclipped = {**params, "TC_A0_TMIN": -1e9, "TC_A0_TMAX": 1e9}
    assert np.max(np.abs(px4_offsets_m_s2(unclipped, 0, outside[[0, 3]]) - offsets[[0, 3]])) > 1e-3


def test_what_px4_cannot_hold_is_stated_with_its_size_on_stderr_and_in_the_file(fitted_paper_campaign, tmp_path,
                                                                                capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    sensor = load_calibration(calibration_path).channel("ADX355-A001", "accel")
    out, notes = px4_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A001")
    assert set(notes) <= written_comments(out)
    assert any("in the sensor chip's own x, y, z" in note for note in notes)  # the stack's axes may differ
    low, high = sensor.validity_c
    parameters = sensor.parameters_at(np.linspace(low, high, 1001))
    scale_ppm, = stated(r"scale error up to (\d+) ppm", notes)
    assert scale_ppm == pytest.approx(np.max(np.abs(parameters[:, 3:6] - 1)) * 1e6, abs=1.0)
    nonorth, misalign = stated(r"non-orthogonality up to ([\d.]+) mrad and misalignment up to ([\d.]+) mrad", notes)
    assert nonorth == pytest.approx(np.max(np.abs(parameters[:, 6:9])) * 1e3, abs=1e-3)
    assert misalign == pytest.approx(np.max(np.abs(parameters[:, 9:12])) * 1e3, abs=1e-3)
    # What leaving them out costs: a sensor with these parameters, corrected for its bias only, at 1 g.
    left_mg, = stated(r"together up to ([\d.]+) mg at 1 g left uncorrected", notes)
    directions = np.random.default_rng(5).normal(size=(4000, 3))
    truth_g = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    worst = 0.0
    for p in parameters[::50]:
        error_mg = np.linalg.norm(distort(truth_g, p) - p[:3] - truth_g, axis=1) * 1e3
        worst = max(worst, float(error_mg.max()))
    assert 0.97 * left_mg <= worst <= left_mg + 5e-4
    assert scale_ppm > 1000 and left_mg > 1.0  # this sensor's are large: the statement matters
    temperatures = stated(r"calibrated (-?[\d.]+) to (-?[\d.]+) degC .* written (-?[\d.]+) to (-?[\d.]+) degC", notes)
    assert temperatures == pytest.approx([low, high, low, high], abs=0.005)
    assert any("TC_A0_ID is 0" in note and "--device-id" in note for note in notes)


def test_to_standard_output_the_file_and_on_stderr_the_notes(fitted_paper_campaign, capsys) -> None:
    code, out, notes = export(capsys, [str(fitted_paper_campaign[1]), "--format", "px4-params", "--serial",
                                       "ADX355-A002"])
    assert code == 0 and out.startswith("# PX4 accelerometer thermal compensation (TC_A0_) for sensor ADX355-A002")
    assert "\n1\t1\tTC_A0_X0_0\t" in out and all(f"# {note}\n" in out for note in notes) and len(notes) >= 3


def test_serial_picks_the_sensor_and_an_unknown_or_missing_one_is_one_line(fitted_paper_campaign, tmp_path,
                                                                           capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    calibration = load_calibration(calibration_path)
    x0 = {}
    for serial in ("ADX355-A001", "ADX355-A002"):
        params = read_qgc_params(px4_export(capsys, calibration_path, tmp_path, "--serial", serial)[0])
        x0[serial] = params["TC_A0_X0_0"]
        bias_x = -bias_removed_m_s2(calibration.channel(serial, "accel"), np.zeros((1, 3)), params["TC_A0_TREF"])[0, 0]
        assert x0[serial] == pytest.approx(bias_x, rel=1e-8)
    assert abs(x0["ADX355-A001"] - x0["ADX355-A002"]) > 1e-3
    for options, expected in (([], ["choose one with --serial", *calibration.of_quantity("acceleration")]),
                              (["--serial", "NOPE"], ["no sensor 'NOPE'", "ADX355-A004"])):
        assert main(["export", str(calibration_path), "--format", "px4-params", *options]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and err.startswith(f"rig: error: {calibration_path}: sensors: ")
        assert all(word in err for word in expected), err


def test_instance_and_device_id(fitted_paper_campaign, tmp_path, capsys) -> None:
    calibration_path = fitted_paper_campaign[1]
    out, notes = px4_export(capsys, calibration_path, tmp_path, "--serial", "ADX355-A004", "--instance", "3",
                            "--device-id", "1310988")
    params = read_qgc_params(out)
    assert params["TC_A3_ID"] == 1310988 and all(n.startswith(("TC_A3_", "TC_A_ENABLE")) for n in params)
    assert len(params) == 1 + 4 + 12 and not any("ID is 0" in note for note in notes)
    for bad in (["--instance", "4"], ["--device-id", "0"]):
        with pytest.raises(SystemExit) as stop:
            main(["export", str(calibration_path), "--format", "px4-params", "--serial", "ADX355-A004", *bad])
        assert stop.value.code == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
