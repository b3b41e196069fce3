"""The C header, compiled with the system C compiler, gives what the Python `apply` gives."""

from __future__ import annotations

import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.export.c_header import c_identifier, to_c_header
from accelcal_rig.fit.calibration import CalibrationFile, CalibrationRangeWarning, apply, apply_codes, load_calibration

PROGRAM = r"""
#include <stdio.h>
#include "calibration.h"

/* Reads lines "sensor temperature_c a b c codes", prints the compensated reading in g. */
int main(void)
{
    int sensor, codes;
    double t, v[3];
    while (scanf("%d %lf %lf %lf %lf %d", &sensor, &t, &v[0], &v[1], &v[2], &codes) == 6) {
        ACCELCAL_REAL out[3];
        if (codes) {
            const int32_t c[3] = {(int32_t)v[0], (int32_t)v[1], (int32_t)v[2]};
            accelcal_apply_codes(&ACCELCAL_SENSORS[sensor], (ACCELCAL_REAL)t, c, out);
        } else {
            const ACCELCAL_REAL raw[3] = {(ACCELCAL_REAL)v[0], (ACCELCAL_REAL)v[1], (ACCELCAL_REAL)v[2]};
            accelcal_apply(&ACCELCAL_SENSORS[sensor], (ACCELCAL_REAL)t, raw, out);
        }
        printf("%.17g %.17g %.17g\n", (double)out[0], (double)out[1], (double)out[2]);
    }
    return 0;
}
"""


def compiler() -> str:
    found = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    assert found, "a C compiler (cc, gcc or clang) is needed to test the exported C header"
    return found


def run_c(header: str, folder: Path, stdin: str, real: str = "double") -> np.ndarray:
    (folder / "calibration.h").write_text(header)
    (folder / "main.c").write_text(PROGRAM)
    executable = folder / f"apply_{real}"
    subprocess.run([compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-DACCELCAL_REAL={real}",
                    "-O2", "-o", str(executable), str(folder / "main.c"), "-lm"], check=True, capture_output=True,
                   text=True)
    out = subprocess.run([str(executable)], input=stdin, check=True, capture_output=True, text=True).stdout
    result = np.loadtxt(out.splitlines(), ndmin=2)
    assert result.shape == (stdin.count("\n"), 3), out[:200]
    return result


def inputs(calibration: CalibrationFile, n: int = 400) -> tuple[list[str], np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Random readings of each sensor from −60 to 80 °C (beyond the calibrated range on both sides), half
    as g and half as 20-bit codes."""
    rng = np.random.default_rng(7)
    serials = list(calibration.of_quantity("acceleration"))
    sensor = rng.integers(0, len(serials), n)
    temperature = rng.uniform(-60.0, 80.0, n)
    direction = rng.normal(size=(n, 3))
    reading = direction / np.linalg.norm(direction, axis=1, keepdims=True) * rng.uniform(0.5, 1.5, (n, 1))
    codes = rng.random(n) < 0.5
    lsb = np.array([calibration.of_quantity("acceleration")[serials[i]].lsb for i in sensor])
    reading[codes] = np.rint(reading[codes] / lsb[codes, None])
    return serials, sensor, temperature, reading, codes


def python_apply(calibration: CalibrationFile, serials, sensor, temperature, reading, codes) -> np.ndarray:
    expected = np.empty_like(reading)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        for i in range(len(sensor)):
            cal = calibration.of_quantity("acceleration")[serials[sensor[i]]]
            f = apply_codes if codes[i] else apply
            expected[i] = f(cal, reading[i], temperature[i])
    return expected


@pytest.fixture(scope="module")
def calibration(fitted_paper_campaign: tuple[Path, Path]) -> CalibrationFile:
    return load_calibration(fitted_paper_campaign[1])


@pytest.mark.parametrize("out_of_range", ["clamp", "extrapolate"])
def test_compiled_header_matches_python_apply(calibration: CalibrationFile, tmp_path: Path, out_of_range: str) -> None:
    for serial, sensor in calibration.of_quantity("acceleration").items():
        calibration = calibration.with_channels(serial, {"accel": sensor.model_copy(update={"out_of_range": out_of_range})})
    serials, sensor, temperature, reading, codes = inputs(calibration)
    stdin = "".join(f"{s} {float(t)!r} {float(a)!r} {float(b)!r} {float(c)!r} {int(k)}\n"
                    for s, t, (a, b, c), k in zip(sensor, temperature, reading, codes))
    expected = python_apply(calibration, serials, sensor, temperature, reading, codes)
    header = to_c_header(calibration)
    in_double = run_c(header, tmp_path, stdin)
    assert np.max(np.abs(in_double - expected)) < 1e-12  # g: the same arithmetic up to rounding
    in_float = run_c(header, tmp_path, stdin, real="float")
    assert np.max(np.abs(in_float - expected)) < 5e-6  # g: single precision, well under the noise floor
    assert np.max(np.abs(expected - reading * np.where(codes, 3.90625e-06, 1.0)[:, None])) > 1e-3  # it did compensate


def test_header_names_each_sensor_by_serial(calibration: CalibrationFile) -> None:
    header = to_c_header(calibration)
    for index, serial in enumerate(calibration.of_quantity("acceleration")):
        assert f"#define ACCELCAL_SENSOR_{c_identifier(serial)} {index}" in header
        assert f'"{serial}"' in header
    assert c_identifier("7-up.b") == "_7_UP_B"
