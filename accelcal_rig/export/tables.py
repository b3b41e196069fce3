"""JSON (the calibration file's own structure, every channel) and CSV (one row per sensor, channel and
parameter of its channel model)."""

from __future__ import annotations

import csv
import io
import json

from accelcal_rig.fit.calibration import CalibrationFile


def to_json(calibration: CalibrationFile) -> str:
    """The calibration file as JSON: the same keys as the YAML, for tools without a YAML reader."""
    return json.dumps(calibration.model_dump(mode="json"), indent=2) + "\n"


def to_csv(calibration: CalibrationFile) -> str:
    """Per sensor, channel and parameter of its model: p(T) = Σ c_k · x^k with x = (T − t_mid_c) /
    t_half_range_c, T in °C the sensor's own temperature clamped to (or extrapolated beyond) t_min_c…t_max_c as
    `out_of_range` says; `lsb` the channel's unit per code."""
    calibrated = calibration.calibrated()
    degree = max(c.polynomial.degree for _, _, c in calibrated)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["serial", "channel", "model", "unit", "parameter", "t_mid_c", "t_half_range_c", "t_min_c",
                     "t_max_c", "out_of_range", "lsb", *(f"c{k}" for k in range(degree + 1))])
    for serial, channel, sensor in calibrated:
        low, high = sensor.polynomial.domain_c
        for name, row in zip(sensor.parameter_names, sensor.polynomial.matrix()):
            coefficients = [*row, *([0.0] * (degree + 1 - len(row)))]
            writer.writerow([serial, channel, sensor.model, sensor.unit, name, repr(0.5 * (low + high)),
                             repr(0.5 * (high - low)), repr(sensor.validity_c[0]), repr(sensor.validity_c[1]),
                             sensor.out_of_range, repr(sensor.lsb), *(repr(float(c)) for c in coefficients)])
    return out.getvalue()
