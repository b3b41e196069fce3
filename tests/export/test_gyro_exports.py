"""A calibrated gyroscope in every export: the PX4 and ArduPilot files re-applied with each stack's formula
written again here (PX4's calc_thermal_offsets_3D and Gyroscope::Correct; ArduPilot's TCal::correct_sensor with
the offsets its boot-time gyro calibration would hold) remove the calibration's `bias_*_dps` polynomial over the
calibrated range; the sizes stated of what they cannot hold match the model's parameters; the C header,
compiled, compensates as `apply` does; csv holds it beside the accelerometer."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.export.c_header import c_identifier, to_c_header
from accelcal_rig.export.flight_stack import StackOptions
from accelcal_rig.export.formats import export as export_format
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.calibration import CalibrationRangeWarning, ChannelCalibration, apply, load_calibration
from tests.conftest import REPO
from tests.export.stack_support import export, stated, written_comments
from tests.export.test_ardupilot import read_ardupilot_params
from tests.export.test_c_header import compiler
from tests.export.test_px4 import read_qgc_params

#: tests/fit/test_gyro_fit.py's small IMU campaign, copied: 0 and 40 °C, rates ±10/±100/±1000 °/s.
PROCEDURE = {
    "name": "imu-small", "rig": str(REPO / "configs" / "sim-imu.yaml"), "setpoints_c": [0, 40],
    "soak": {"criterion": "settling", "min_dwell_min": 10, "window_min": 10, "poll_s": 60},
    "schedule": {"kind": "paper-24"},
    "acquisition": {"samples_per_pose": 100, "range_g": 2, "range_dps": 2000, "odr_hz": 100, "settle_s": 1},
    "rates": {"rates_dps": [10, 100, 1000], "settle_s": 1, "verify_rates_dps": [30, 500]},
    "noise": {"duration_s": 20},
    "fit": {"mode": "reference", "polynomial_degree": 1},
    "verify": {"schedule": {"kind": "sphere", "count": 6}, "at_setpoints": False, "setpoints_c": [20]},
}
RAD = np.pi / 180.0  # both stacks take rates in rad/s
SERIAL = "IMU-A001"


@pytest.fixture(scope="module")
def imu_calibration(imu_dry_run: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """tests/fit/test_gyro_fit.py's small IMU campaign (0 and 40 °C, seed 3), fitted: a calibration whose four
    DUTs have an accel and a gyro channel (this module's copy of tests/conftest.py's imu_dry_run)."""
    from tests.report.imu_campaign import copied

    return copied(imu_dry_run, tmp_path_factory.mktemp("imu-export"))[1]


def bias_rad_s(gyro: ChannelCalibration, temperature_c: np.ndarray) -> np.ndarray:
    """The calibration's own bias polynomials (bias_x_dps …) at each temperature, in rad/s."""
    return gyro.polynomial.at(temperature_c)[..., :3] * RAD


def stack_export(capsys, calibration: Path, folder: Path, fmt: str, *options: str) -> tuple[Path, list[str]]:
    out = folder / ("px4.params" if fmt == "px4-params" else "tcal.param")
    code, stdout, notes = export(capsys, [str(calibration), "--format", fmt, *options, "-o", str(out)])
    assert code == 0 and stdout.startswith(f"{fmt} of sensor ")
    return out, notes


def px4_gyro_offsets(params: dict[str, float], n: int, temperature_c: np.ndarray, real=np.float64) -> np.ndarray:
    """calc_thermal_offsets_3D on TC_G<n>_: T clipped to TMIN…TMAX, dT = T - TREF, X0 + X1 dT + X2 dT² + X3 dT³,
    in `real` arithmetic (PX4 computes in float32)."""
    p = f"TC_G{n}_"
    t = np.asarray(temperature_c, dtype=real)
    dt = np.minimum(np.maximum(t, real(params[p + "TMIN"])), real(params[p + "TMAX"])) - real(params[p + "TREF"])
    return np.stack([real(params[f"{p}X0_{i}"]) + real(params[f"{p}X1_{i}"]) * dt + real(params[f"{p}X2_{i}"]) * dt * dt
                     + real(params[f"{p}X3_{i}"]) * dt * dt * dt for i in range(3)], axis=-1)


def px4_bound(params: dict[str, float], n: int, temperature_c: np.ndarray, relative: float) -> np.ndarray:
    p = f"TC_G{n}_"
    dt = np.abs(np.clip(temperature_c, params[p + "TMIN"], params[p + "TMAX"]) - params[p + "TREF"])
    return np.stack([sum(abs(params[f"{p}X{k}_{i}"]) * dt**k for k in range(4)) for i in range(3)], -1) * relative


def test_px4_removes_the_gyro_bias_polynomial(imu_calibration, tmp_path, capsys) -> None:
    calibration = load_calibration(imu_calibration)
    rng = np.random.default_rng(17)
    for n, (serial, gyro) in enumerate(calibration.of_quantity("angular rate").items()):
        out, notes = stack_export(capsys, imu_calibration, tmp_path, "px4-params", "--serial", serial,
                                  "--instance", str(n), "--device-id", str(1000 + n))
        params = read_qgc_params(out)
        assert params["TC_G_ENABLE"] == 1 and params["TC_A_ENABLE"] == 1
        assert params[f"TC_G{n}_ID"] == params[f"TC_A{n}_ID"] == 1000 + n
        assert len([k for k in params if k.startswith(f"TC_G{n}_")]) == 4 + 12
        low, high = gyro.validity_c
        assert (params[f"TC_G{n}_TMIN"], params[f"TC_G{n}_TMAX"]) == pytest.approx((low, high), abs=1e-6)
        assert params[f"TC_G{n}_TREF"] == pytest.approx(0.5 * (low + high), abs=0.005)
        temperature = np.linspace(low, high, 301)
        raw = rng.normal(0.0, 1.0, (temperature.size, 3))  # rad/s
        # Gyroscope::Correct with CAL_GYRO offsets 0 and no rotation: data - thermal offset.
        corrected = raw - px4_gyro_offsets(params, n, temperature)
        difference = np.abs(corrected - (raw - bias_rad_s(gyro, temperature)))
        assert np.all(difference <= px4_bound(params, n, temperature, 1e-8) + 1e-15), difference.max()
        # As PX4 evaluates it, in float32: within float32's rounding of the terms.
        in_float = px4_gyro_offsets(params, n, temperature, real=np.float32).astype(float)
        assert np.all(np.abs(in_float - bias_rad_s(gyro, temperature))
                      <= px4_bound(params, n, temperature, 1e-6) + 1e-12)
        assert not any("gyro channel is not in this export" in note for note in notes)
        assert any(f"TC_G{n}_ID is --device-id as TC_A{n}_ID" in note for note in notes)


def test_px4_clips_the_gyro_temperature_and_states_its_offset(imu_calibration, tmp_path, capsys) -> None:
    gyro = load_calibration(imu_calibration).channel(SERIAL, "gyro")
    out, notes = stack_export(capsys, imu_calibration, tmp_path, "px4-params", "--serial", SERIAL)
    params = read_qgc_params(out)
    low, high = gyro.validity_c
    outside = np.array([low - 30.0, high + 30.0])
    np.testing.assert_allclose(px4_gyro_offsets(params, 0, outside), bias_rad_s(gyro, np.array([low, high])),
                               rtol=0, atol=1e-9)
    x0 = stated(r"TC_G0_X0_ holds the gyro offset at TREF = [\d.]+ degC \((-?[\d.]+), (-?[\d.]+), (-?[\d.]+) deg/s",
                notes)
    assert x0 == pytest.approx(bias_rad_s(gyro, params["TC_G0_TREF"]) / RAD, abs=1e-5)
    assert any("TC_G0_ID is 0" in note for note in notes) and set(notes) <= written_comments(out)


def ardupilot_gyro(params: dict[str, float], n: int, raw: np.ndarray, temperature_c: np.ndarray, cal_temp_c: float,
                   gyro_offset: np.ndarray) -> np.ndarray:
    """_rotate_and_correct_gyro in the sensor frame: TCal::correct_sensor on GYR1…GYR3 (polynomial_eval without a
    constant, ×1e-6, about 35 °C; T and T_cal clipped to TMIN…TMAX), then INS_GYROFFS subtracted."""
    p = f"INS_TCAL{n}_"

    def poly(t: np.ndarray) -> np.ndarray:
        u = np.clip(t, params[p + "TMIN"], params[p + "TMAX"]) - 35.0
        return np.stack([sum(params[f"{p}GYR{k}_{a}"] * u**k for k in (1, 2, 3)) * 1e-6 for a in "XYZ"], -1)

    return raw - poly(temperature_c) + poly(np.array([cal_temp_c])) - gyro_offset


@pytest.mark.parametrize("cal_temp_c", [22.0, 35.0, -60.0])
def test_ardupilot_with_its_boot_gyro_offsets_removes_the_gyro_bias(imu_calibration, tmp_path, capsys,
                                                                    cal_temp_c: float) -> None:
    calibration = load_calibration(imu_calibration)
    rng = np.random.default_rng(23)
    for serial, gyro in calibration.of_quantity("angular rate").items():
        out, notes = stack_export(capsys, imu_calibration, tmp_path, "ardupilot-params", "--serial", serial)
        params = read_ardupilot_params(out)
        assert all(f"INS_TCAL1_GYR{k}_{a}" in params for k in (1, 2, 3) for a in "XYZ") and len(params) == 3 + 18
        # The boot gyro calibration runs with the temperature correction off: INS_GYROFFS is the raw offset at
        # T_cal, the bias there (within the range ArduPilot clips to).
        tmin, tmax = params["INS_TCAL1_TMIN"], params["INS_TCAL1_TMAX"]
        cal_at = np.clip(cal_temp_c, tmin, tmax)
        offset = bias_rad_s(gyro, np.array([cal_at]))
        low, high = max(gyro.validity_c[0], tmin), min(gyro.validity_c[1], tmax)  # the range both hold
        temperature = np.linspace(low, high, 301)
        raw = rng.normal(0.0, 1.0, (temperature.size, 3))
        corrected = ardupilot_gyro(params, 1, raw, temperature, cal_temp_c, offset)
        difference = np.abs(corrected - (raw - bias_rad_s(gyro, temperature)))
        assert np.max(difference) < 1e-9 * np.max(np.abs(offset)) + 1e-12, difference.max()
        shared, = stated(r"which it shares: up to ([\d.]+) deg/s", notes)
        whole = np.linspace(*gyro.validity_c, 301)
        beyond = ardupilot_gyro(params, 1, np.zeros((whole.size, 3)), whole, 35.0, bias_rad_s(gyro, np.array([35.0])))
        assert np.max(np.abs(beyond + bias_rad_s(gyro, whole))) / RAD <= shared + 2e-6
        assert any("INS_GYROFFS_X/Y/Z" in note and "INS_GYR1_CALTEMP" in note for note in notes)
        assert not any("gyro channel is not in this export" in note for note in notes)


def test_what_the_offset_only_model_cannot_hold_is_stated_with_its_sizes(imu_calibration, tmp_path, capsys) -> None:
    gyro = load_calibration(imu_calibration).channel(SERIAL, "gyro")
    for fmt in ("px4-params", "ardupilot-params"):
        out, notes = stack_export(capsys, imu_calibration, tmp_path, fmt, "--serial", SERIAL)
        assert set(notes) <= written_comments(out)
        stack = "PX4" if fmt == "px4-params" else "ArduPilot"
        assert any(note.startswith(f"not exported ({stack} holds gyro offsets only)") for note in notes)
        parameters = gyro.parameters_at(np.linspace(*gyro.validity_c, 1001))
        scale, = stated(r"gyro offsets only\): scale error up to (\d+) ppm", notes)
        assert scale == pytest.approx(np.max(np.abs(parameters[:, gyro_model.SCALE] - 1)) * 1e6, abs=1.0)
        cross, = stated(r"cross-axis sensitivity \(misalignment and non-orthogonality\) up to ([\d.]+) mrad", notes)
        assert cross == pytest.approx(np.max(np.abs(parameters[:, gyro_model.CROSS])) * 1e3, abs=1e-3)
        asym, = stated(r"asymmetry up to (\d+) ppm", notes)
        assert asym == pytest.approx(np.max(np.abs(parameters[:, gyro_model.ASYMMETRY])) * 1e6, abs=1.0)
        nonlin, = stated(r"nonlinearity up to (\d+) ppm", notes)
        assert nonlin == pytest.approx(np.max(np.abs(parameters[:, gyro_model.NONLINEARITY])) * 1e6, abs=1.0)
        gsens, = stated(r"g-sensitivity up to ([\d.]+) deg/s per g", notes)
        norms = np.linalg.norm(gyro_model.gsensitivity_matrix(parameters), ord=2, axis=(1, 2))
        assert gsens == pytest.approx(norms.max(), abs=1e-4)
        # Together: a gyroscope with these parameters at full scale and 1 g, its bias alone removed.
        together, = stated(r"together up to ([\d.]+) deg/s at full scale", notes)
        rng = np.random.default_rng(29)
        worst = 0.0
        for p in parameters[::100]:
            omega = rng.normal(size=(3000, 3))
            omega *= gyro.range / np.linalg.norm(omega, axis=1, keepdims=True)
            force = rng.normal(size=(3000, 3))
            force /= np.linalg.norm(force, axis=1, keepdims=True)
            left = gyro_model.distort_rate(omega, force, p) - p[:3] - omega
            worst = max(worst, float(np.linalg.norm(left, axis=1).max()))
        assert 0.8 * together <= worst <= together + 1e-3
        assert scale > 100 and together > 1.0  # this gyroscope's are large: the statement matters


def test_the_c_header_compensates_gyro_samples_as_apply_does(imu_calibration, tmp_path) -> None:
    calibration = load_calibration(imu_calibration)
    gyros = list(calibration.of_quantity("angular rate").values())
    header = to_c_header(calibration)
    for index, gyro in enumerate(gyros):
        assert f"#define ACCELCAL_GYRO_{c_identifier(gyro.serial)} {index}" in header
    rng = np.random.default_rng(31)
    n = 500
    which = rng.integers(0, len(gyros), n)
    temperature = rng.uniform(-30.0, 70.0, n)  # beyond the calibrated 0…40 °C on both sides
    rate = rng.normal(size=(n, 3)) * rng.uniform(1.0, 1900.0, (n, 1)) / np.sqrt(3)
    force = rng.normal(size=(n, 3))
    force /= np.linalg.norm(force, axis=1, keepdims=True)
    codes = rng.random(n) < 0.3
    rate[codes] = np.rint(rate[codes] / gyros[0].lsb)
    expected = np.empty_like(rate)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        for i in range(n):
            raw = rate[i] * (gyros[which[i]].lsb if codes[i] else 1.0)
            expected[i] = apply(gyros[which[i]], raw, temperature[i], {"acceleration": force[i]})
    stdin = "".join(f"{w} {t!r} {a!r} {b!r} {c!r} {f0!r} {f1!r} {f2!r} {int(k)}\n" for w, t, (a, b, c), (f0, f1, f2), k
                    in zip(which, temperature.tolist(), rate.tolist(), force.tolist(), codes))
    in_double = run_gyro_c(header, tmp_path, stdin, "double")
    assert np.max(np.abs(in_double - expected)) < 1e-9  # deg/s at up to 2000 deg/s: the same arithmetic
    in_float = run_gyro_c(header, tmp_path, stdin, "float")
    assert np.max(np.abs(in_float - expected) / np.maximum(1.0, np.abs(expected))) < 2e-6
    assert np.max(np.abs(expected - rate * np.where(codes, gyros[0].lsb, 1.0)[:, None])) > 1.0  # it did correct


GYRO_PROGRAM = r"""
#include <stdio.h>
#include "calibration.h"

/* Reads lines "gyro temperature_c a b c fx fy fz codes", prints the compensated rate in deg/s. */
int main(void)
{
    int gyro, codes;
    double t, v[3], f[3];
    while (scanf("%d %lf %lf %lf %lf %lf %lf %lf %d", &gyro, &t, &v[0], &v[1], &v[2], &f[0], &f[1], &f[2],
                 &codes) == 9) {
        ACCELCAL_REAL out[3];
        const ACCELCAL_REAL force[3] = {(ACCELCAL_REAL)f[0], (ACCELCAL_REAL)f[1], (ACCELCAL_REAL)f[2]};
        if (codes) {
            const int32_t c[3] = {(int32_t)v[0], (int32_t)v[1], (int32_t)v[2]};
            accelcal_apply_gyro_codes(&ACCELCAL_GYROS[gyro], (ACCELCAL_REAL)t, c, force, out);
        } else {
            const ACCELCAL_REAL raw[3] = {(ACCELCAL_REAL)v[0], (ACCELCAL_REAL)v[1], (ACCELCAL_REAL)v[2]};
            accelcal_apply_gyro(&ACCELCAL_GYROS[gyro], (ACCELCAL_REAL)t, raw, force, out);
        }
        printf("%.17g %.17g %.17g\n", (double)out[0], (double)out[1], (double)out[2]);
    }
    return 0;
}
"""


def run_gyro_c(header: str, folder: Path, stdin: str, real: str) -> np.ndarray:
    import subprocess

    (folder / "calibration.h").write_text(header)
    (folder / "gyro.c").write_text(GYRO_PROGRAM)
    executable = folder / f"gyro_{real}"
    subprocess.run([compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-DACCELCAL_REAL={real}",
                    "-O2", "-o", str(executable), str(folder / "gyro.c"), "-lm"], check=True, capture_output=True,
                   text=True)
    out = subprocess.run([str(executable)], input=stdin, check=True, capture_output=True, text=True).stdout
    result = np.loadtxt(out.splitlines(), ndmin=2)
    assert result.shape == (stdin.count("\n"), 3), out[:200]
    return result


def test_json_csv_and_the_c_header_carry_the_gyro_beside_the_accelerometer(imu_calibration) -> None:
    calibration = load_calibration(imu_calibration)
    options = StackOptions(imu_calibration)
    for fmt in ("json", "c-header", "csv"):
        exported = export_format(calibration, fmt, options)
        assert exported.notes == (), fmt
        assert "bias_x_dps" in exported.text and "bias_x_g" in exported.text, fmt
    rows = [line.split(",") for line in export_format(calibration, "csv", options).text.splitlines()[1:]]
    assert {(row[1], row[2], row[3]) for row in rows} == {("accel", "sfem-eq1", "g"), ("gyro", "gyro-rate-table", "dps")}
    assert len(rows) == 4 * (12 + 27 + 3)  # the gyroscope's scale at its finer range: a row per axis
    scales = [row for row in rows if row[5].startswith("range_scale_")]
    assert {row[4] for row in scales} == {"250.0"} and {row[4] for row in rows if row[1] == "gyro"} == {"250.0", "2000.0"}
    assert all(abs(float(row[12]) - 1.0) < 0.01 for row in scales)
