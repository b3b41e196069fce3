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
    `out_of_range` says; `lsb` the channel's unit per code at `range`, the ± full scale the parameters hold. A
    channel measured at other ranges too (a gyroscope's finer one at rest) has a row per axis and such range,
    `range_scale_<axis>` at that `range`: its readings there divided by c0 before the model."""
    calibrated = calibration.calibrated()
    degree = max(c.polynomial.degree for _, _, c in calibrated)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["serial", "channel", "model", "unit", "range", "parameter", "t_mid_c", "t_half_range_c",
                     "t_min_c", "t_max_c", "out_of_range", "lsb", *(f"c{k}" for k in range(degree + 1))])
    for serial, channel, sensor in calibrated:
        low, high = sensor.polynomial.domain_c
        domain = [repr(0.5 * (low + high)), repr(0.5 * (high - low)), repr(sensor.validity_c[0]),
                  repr(sensor.validity_c[1]), sensor.out_of_range]
        for name, row in zip(sensor.parameter_names, sensor.polynomial.matrix()):
            coefficients = [*row, *([0.0] * (degree + 1 - len(row)))]
            writer.writerow([serial, channel, sensor.model, sensor.unit, repr(sensor.range), name, *domain,
                             repr(sensor.lsb), *(repr(float(c)) for c in coefficients)])
        for other in sensor.range_scales:
            lsb = sensor.lsb * other.range / sensor.range  # the part's codes are one width at every range
            for axis, scale in zip("xyz", other.scale):
                writer.writerow([serial, channel, sensor.model, sensor.unit, repr(other.range), f"range_scale_{axis}",
                                 *domain, repr(lsb), repr(float(scale)), *(["0.0"] * degree)])
    return out.getvalue()
