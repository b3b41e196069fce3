"""A self-contained C header for firmware: every sensor's polynomial coefficients and the functions that
evaluate them and apply Eq. 1, U_SF = M · C · S · (U − b), exactly as `fit.calibration.apply` does; where DUTs
have a calibrated gyroscope, its 27 polynomials and `accelcal_apply_gyro`, which inverts the rate-table model
exactly as `fit.calibration.apply_gyro` (`fit.gyro_model.correct_rate`) does.

C99, no allocation, <math.h> only (sqrt, sin, cos, fabs). `ACCELCAL_REAL` selects double (default) or float.
"""

from __future__ import annotations

import re

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.calibration import CalibrationFile, GyroCalibration
from accelcal_rig.fit.sfem import PARAMETER_NAMES

#: Newton steps on each axis's scale curve: as many as `gyro_model.correct_rate` takes.
_GYRO_NEWTON_STEPS = gyro_model._INVERSE_STEPS  # noqa: SLF001 - the same count, so the same result

_GYRO_FUNCTIONS = r"""
/* The gyroscope model's 27 parameters at its own temperature (deg C), as accelcal_parameters. */
static inline void accelcal_gyro_parameters(const accelcal_gyro *g, ACCELCAL_REAL temperature_c,
                                            ACCELCAL_REAL p[ACCELCAL_GYRO_N_PARAMETERS])
{
    ACCELCAL_REAL t = temperature_c;
    if (g->clamp) {
        if (t < g->t_min_c) t = g->t_min_c;
        if (t > g->t_max_c) t = g->t_max_c;
    }
    const ACCELCAL_REAL x = (t - g->t_mid_c) / g->t_half_range_c;
    for (int k = 0; k < ACCELCAL_GYRO_N_PARAMETERS; ++k) {
        ACCELCAL_REAL value = 0;
        for (int j = ACCELCAL_GYRO_DEGREE; j >= 0; --j) value = value * x + g->coefficients[k][j];
        p[k] = value;
    }
}

/* Compensate one raw gyroscope reading (deg/s, codes x lsb_dps) taken at the gyroscope's temperature (deg C)
 * while it felt the specific force force_g (g, the compensated accelerometer's reading): the model
 * raw = b + u + a|u| + n u (u/1000)^2 + G f, u = K w, solved for the true rate w (deg/s). Bias and
 * g-sensitivity come off, each axis's scale curve is inverted by Newton's method, then K. */
static inline void accelcal_apply_gyro(const accelcal_gyro *g, ACCELCAL_REAL temperature_c,
                                       const ACCELCAL_REAL raw_dps[3], const ACCELCAL_REAL force_g[3],
                                       ACCELCAL_REAL out_dps[3])
{
    ACCELCAL_REAL p[ACCELCAL_GYRO_N_PARAMETERS], u[3];
    accelcal_gyro_parameters(g, temperature_c, p);
    for (int i = 0; i < 3; ++i) {
        const ACCELCAL_REAL *gs = &p[18 + 3 * i];
        const ACCELCAL_REAL target = raw_dps[i] - p[i] - (gs[0] * force_g[0] + gs[1] * force_g[1] + gs[2] * force_g[2]);
        const ACCELCAL_REAL a = p[12 + i], n = p[15 + i];
        ACCELCAL_REAL v = target;
        for (int step = 0; step < ACCELCAL_GYRO_NEWTON_STEPS; ++step) {
            const ACCELCAL_REAL r = v / ACCELCAL_GYRO_NONLINEARITY_RATE_DPS;
            const ACCELCAL_REAL sign = (ACCELCAL_REAL)((v > 0) - (v < 0));
            const ACCELCAL_REAL curve = v + a * fabs(v) + n * v * r * r;
            v = v - (curve - target) / (1 + a * sign + 3 * n * r * r);
        }
        u[i] = v;
    }
    /* K: scale factors on the diagonal, cross terms xy, xz, yx, yz, zx, zy off it; out = K^-1 u (adjugate). */
    const ACCELCAL_REAL k[3][3] = {{p[3], p[6], p[7]}, {p[8], p[4], p[9]}, {p[10], p[11], p[5]}};
    const ACCELCAL_REAL c00 = k[1][1] * k[2][2] - k[1][2] * k[2][1];
    const ACCELCAL_REAL c01 = k[1][2] * k[2][0] - k[1][0] * k[2][2];
    const ACCELCAL_REAL c02 = k[1][0] * k[2][1] - k[1][1] * k[2][0];
    const ACCELCAL_REAL det = k[0][0] * c00 + k[0][1] * c01 + k[0][2] * c02;
    const ACCELCAL_REAL inv[3][3] = {
        {c00, k[0][2] * k[2][1] - k[0][1] * k[2][2], k[0][1] * k[1][2] - k[0][2] * k[1][1]},
        {c01, k[0][0] * k[2][2] - k[0][2] * k[2][0], k[0][2] * k[1][0] - k[0][0] * k[1][2]},
        {c02, k[0][1] * k[2][0] - k[0][0] * k[2][1], k[0][0] * k[1][1] - k[0][1] * k[1][0]}};
    for (int i = 0; i < 3; ++i) out_dps[i] = (inv[i][0] * u[0] + inv[i][1] * u[1] + inv[i][2] * u[2]) / det;
}

/* As accelcal_apply_gyro, from signed gyroscope codes at the calibrated range. */
static inline void accelcal_apply_gyro_codes(const accelcal_gyro *g, ACCELCAL_REAL temperature_c,
                                             const int32_t codes[3], const ACCELCAL_REAL force_g[3],
                                             ACCELCAL_REAL out_dps[3])
{
    const ACCELCAL_REAL raw_dps[3] = {codes[0] * g->lsb_dps, codes[1] * g->lsb_dps, codes[2] * g->lsb_dps};
    accelcal_apply_gyro(g, temperature_c, raw_dps, force_g, out_dps);
}
"""

_FUNCTIONS = r"""
/* Eq. 1 parameters at the sensor's own temperature (deg C): p[k] = sum_j c[k][j] * x^j (Horner),
 * x = (T - t_mid_c) / t_half_range_c, T first clamped to t_min_c..t_max_c when clamp is 1. */
static inline void accelcal_parameters(const accelcal_sensor *s, ACCELCAL_REAL temperature_c,
                                       ACCELCAL_REAL p[ACCELCAL_N_PARAMETERS])
{
    ACCELCAL_REAL t = temperature_c;
    if (s->clamp) {
        if (t < s->t_min_c) t = s->t_min_c;
        if (t > s->t_max_c) t = s->t_max_c;
    }
    const ACCELCAL_REAL x = (t - s->t_mid_c) / s->t_half_range_c;
    for (int k = 0; k < ACCELCAL_N_PARAMETERS; ++k) {
        ACCELCAL_REAL value = 0;
        for (int j = ACCELCAL_DEGREE; j >= 0; --j) value = value * x + s->coefficients[k][j];
        p[k] = value;
    }
}

/* Misalignment M from its rotation vector r (rad): Rodrigues' formula, with the series near zero. */
static inline void accelcal_rotation(const ACCELCAL_REAL r[3], ACCELCAL_REAL m[3][3])
{
    const ACCELCAL_REAL theta2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    ACCELCAL_REAL a, b; /* sin(theta)/theta and (1 - cos(theta))/theta^2 */
    if (theta2 < (ACCELCAL_REAL)1e-8) {
        a = 1 - theta2 / 6;
        b = (ACCELCAL_REAL)0.5 - theta2 / 24;
    } else {
        const ACCELCAL_REAL theta = sqrt(theta2);
        a = sin(theta) / theta;
        b = (1 - cos(theta)) / theta2;
    }
    const ACCELCAL_REAL k[3][3] = {{0, -r[2], r[1]}, {r[2], 0, -r[0]}, {-r[1], r[0], 0}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            ACCELCAL_REAL k2 = 0;
            for (int n = 0; n < 3; ++n) k2 += k[i][n] * k[n][j];
            m[i][j] = (i == j) + a * k[i][j] + b * k2;
        }
}

/* Compensate one raw reading (g, codes x lsb_g) taken at the sensor's temperature (deg C):
 * out = M * C * S * (raw - b), C lower unit-triangular (nonorth yx, zx, zy), S diagonal. */
static inline void accelcal_apply(const accelcal_sensor *s, ACCELCAL_REAL temperature_c,
                                  const ACCELCAL_REAL raw_g[3], ACCELCAL_REAL out_g[3])
{
    ACCELCAL_REAL p[ACCELCAL_N_PARAMETERS], m[3][3];
    accelcal_parameters(s, temperature_c, p);
    const ACCELCAL_REAL u0 = p[3] * (raw_g[0] - p[0]);
    const ACCELCAL_REAL u1 = p[4] * (raw_g[1] - p[1]);
    const ACCELCAL_REAL u2 = p[5] * (raw_g[2] - p[2]);
    const ACCELCAL_REAL c[3] = {u0, p[6] * u0 + u1, p[7] * u0 + p[8] * u1 + u2};
    accelcal_rotation(&p[9], m);
    for (int i = 0; i < 3; ++i) out_g[i] = m[i][0] * c[0] + m[i][1] * c[1] + m[i][2] * c[2];
}

/* As accelcal_apply, from signed 20-bit ADXL355 codes at the calibrated range. */
static inline void accelcal_apply_codes(const accelcal_sensor *s, ACCELCAL_REAL temperature_c,
                                        const int32_t codes[3], ACCELCAL_REAL out_g[3])
{
    const ACCELCAL_REAL raw_g[3] = {codes[0] * s->lsb_g, codes[1] * s->lsb_g, codes[2] * s->lsb_g};
    accelcal_apply(s, temperature_c, raw_g, out_g);
}
"""


def c_identifier(serial: str) -> str:
    """`ADX355-A001` → `ADX355_A001`, a valid C identifier."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", serial).upper()
    return name if not name[0].isdigit() else "_" + name


def to_c_header(calibration: CalibrationFile, guard: str = "ACCELCAL_CALIBRATION_H") -> str:
    sensors = list(calibration.sensors.values())
    degree = max(s.polynomial.degree for s in sensors)
    lines = [
        f"/* {calibration.format} for firmware, generated by accelcal-rig {calibration.software_version}.",
        f" * Calibration created {calibration.created} from {calibration.source.get('campaign', '?')}"
        f" (procedure {calibration.source.get('procedure', '?')}).",
        " * Model: paper Eq. 1, U_SF = M * C * S * (U - b); each parameter a polynomial of the sensor's own",
        " * temperature (Eq. 8). Parameter order: " + ", ".join(PARAMETER_NAMES) + ".",
        " * Usage: accelcal_apply(&ACCELCAL_SENSORS[ACCELCAL_SENSOR_<SERIAL>], temperature_c, raw_g, out_g); */",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "#include <math.h>",
        "#include <stdint.h>",
        "",
        "#ifndef ACCELCAL_REAL",
        "#define ACCELCAL_REAL double",
        "#endif",
        "#define ACCELCAL_N_PARAMETERS 12",
        f"#define ACCELCAL_DEGREE {degree}",
        f"#define ACCELCAL_N_SENSORS {len(sensors)}",
        "",
        "typedef struct {",
        "    const char *serial;",
        "    ACCELCAL_REAL lsb_g;                 /* g per 20-bit code at the calibrated range */",
        "    ACCELCAL_REAL t_mid_c, t_half_range_c; /* x = (T - t_mid_c) / t_half_range_c */",
        "    ACCELCAL_REAL t_min_c, t_max_c;      /* calibrated temperature range */",
        "    int clamp;                           /* 1: T clamped to the range; 0: extrapolated */",
        "    ACCELCAL_REAL coefficients[ACCELCAL_N_PARAMETERS][ACCELCAL_DEGREE + 1]; /* increasing powers of x */",
        "} accelcal_sensor;",
        "",
    ]
    lines += [f"#define ACCELCAL_SENSOR_{c_identifier(s.serial)} {i}" for i, s in enumerate(sensors)]
    lines += ["", "static const accelcal_sensor ACCELCAL_SENSORS[ACCELCAL_N_SENSORS] = {"]
    for sensor in sensors:
        low, high = sensor.polynomial.domain_c
        matrix = sensor.polynomial.matrix()
        lines += [
            "    {",
            f"        \"{sensor.serial}\", {sensor.lsb_g!r}, {0.5 * (low + high)!r}, {0.5 * (high - low)!r},",
            f"        {sensor.validity_c[0]!r}, {sensor.validity_c[1]!r}, {int(sensor.out_of_range == 'clamp')},",
            "        {",
        ]
        for name, row in zip(PARAMETER_NAMES, matrix):
            values = [*map(float, row), *([0.0] * (degree + 1 - len(row)))]
            lines.append(f"            {{{', '.join(repr(v) for v in values)}}}, /* {name} */")
        lines += ["        },", "    },"]
    lines += ["};", _FUNCTIONS]
    gyros = list(calibration.gyroscopes.values())
    if gyros:
        lines += _gyro_section(gyros)
    lines += [f"#endif /* {guard} */", ""]
    return "\n".join(lines)


def _gyro_section(gyros: list[GyroCalibration]) -> list[str]:
    """The gyroscopes' type, coefficients (indexed by ACCELCAL_GYRO_<SERIAL>) and functions."""
    assert list(gyro_model.PARAMETER_NAMES[12:18]) == [f"{t}_{a}" for t in ("asymmetry", "nonlinearity")
                                                       for a in "xyz"]  # the offsets the C code uses
    degree = max(g.polynomial.degree for g in gyros)
    lines = [
        "/* Gyroscopes calibrated on a rate table (model gyro-rate-table, fit/gyro_model.py), per temperature:",
        " * raw = b + u + a|u| + n u (u/1000)^2 + G f, u = K w. Parameter order: "
        + ", ".join(gyro_model.PARAMETER_NAMES) + ".",
        " * Usage: accelcal_apply_gyro(&ACCELCAL_GYROS[ACCELCAL_GYRO_<SERIAL>], temperature_c, raw_dps, force_g,"
        " out_dps); */",
        f"#define ACCELCAL_GYRO_N_PARAMETERS {gyro_model.N_PARAMETERS}",
        f"#define ACCELCAL_GYRO_DEGREE {degree}",
        f"#define ACCELCAL_N_GYROS {len(gyros)}",
        f"#define ACCELCAL_GYRO_NEWTON_STEPS {_GYRO_NEWTON_STEPS}",
        f"#define ACCELCAL_GYRO_NONLINEARITY_RATE_DPS {gyro_model.NONLINEARITY_RATE_DPS!r}",
        "",
        "typedef struct {",
        "    const char *serial;",
        "    ACCELCAL_REAL lsb_dps;               /* deg/s per code at the calibrated range */",
        "    ACCELCAL_REAL t_mid_c, t_half_range_c; /* x = (T - t_mid_c) / t_half_range_c */",
        "    ACCELCAL_REAL t_min_c, t_max_c;      /* calibrated temperature range */",
        "    int clamp;                           /* 1: T clamped to the range; 0: extrapolated */",
        "    ACCELCAL_REAL coefficients[ACCELCAL_GYRO_N_PARAMETERS][ACCELCAL_GYRO_DEGREE + 1]; /* increasing powers */",
        "} accelcal_gyro;",
        "",
    ]
    lines += [f"#define ACCELCAL_GYRO_{c_identifier(g.serial)} {i}" for i, g in enumerate(gyros)]
    lines += ["", "static const accelcal_gyro ACCELCAL_GYROS[ACCELCAL_N_GYROS] = {"]
    for gyro in gyros:
        low, high = gyro.polynomial.domain_c
        lines += [
            "    {",
            f"        \"{gyro.serial}\", {gyro.lsb_dps!r}, {0.5 * (low + high)!r}, {0.5 * (high - low)!r},",
            f"        {gyro.validity_c[0]!r}, {gyro.validity_c[1]!r}, {int(gyro.out_of_range == 'clamp')},",
            "        {",
        ]
        for name, row in zip(gyro_model.PARAMETER_NAMES, gyro.polynomial.matrix()):
            values = [*map(float, row), *([0.0] * (degree + 1 - len(row)))]
            lines.append(f"            {{{', '.join(repr(v) for v in values)}}}, /* {name} */")
        lines += ["        },", "    },"]
    lines += ["};", _GYRO_FUNCTIONS]
    return lines
