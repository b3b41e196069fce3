"""JSON (the calibration file's own structure, every channel) and CSV (one row per sensor and accelerometer
parameter: a calibrated gyroscope is left out, and `formats.not_exported` says so)."""

from __future__ import annotations

import csv
import io
import json

from accelcal_rig.fit.calibration import CalibrationFile
from accelcal_rig.fit.sfem import PARAMETER_NAMES


def to_json(calibration: CalibrationFile) -> str:
    """The calibration file as JSON: the same keys as the YAML, for tools without a YAML reader."""
    return json.dumps(calibration.model_dump(mode="json"), indent=2) + "\n"


def to_csv(calibration: CalibrationFile) -> str:
    """Per sensor and parameter: p(T) = Σ c_k · x^k with x = (T − t_mid_c) / t_half_range_c, T in °C the
    sensor's own temperature clamped to (or extrapolated beyond) t_min_c…t_max_c as `out_of_range` says."""
    degree = max(s.polynomial.degree for s in calibration.sensors.values())
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["serial", "parameter", "t_mid_c", "t_half_range_c", "t_min_c", "t_max_c", "out_of_range",
                     "lsb_g", *(f"c{k}" for k in range(degree + 1))])
    for serial, sensor in calibration.sensors.items():
        low, high = sensor.polynomial.domain_c
        for name, row in zip(PARAMETER_NAMES, sensor.polynomial.matrix()):
            coefficients = [*row, *([0.0] * (degree + 1 - len(row)))]
            writer.writerow([serial, name, repr(0.5 * (low + high)), repr(0.5 * (high - low)),
                             repr(sensor.validity_c[0]), repr(sensor.validity_c[1]), sensor.out_of_range,
                             repr(sensor.lsb_g), *(repr(float(c)) for c in coefficients)])
    return out.getvalue()
