"""Eq. 1 in C for the C header (export/c_header.py): the functions that evaluate a channel's polynomials and
apply U_SF = M · C · S · (U − b) exactly as `fit.sfem.correct` does, for any quantity an Eq. 1 model calibrates
(an accelerometer's names are the header's first ones, kept; another quantity's carry its token)."""

from __future__ import annotations

from accelcal_rig.fit.channel_model import CExport

#: Misalignment M from its rotation vector, shared by every Eq. 1 section of a header.
ROTATION = r"""
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
"""

_FUNCTIONS = r"""
/* Eq. 1 parameters at the sensor's own temperature (deg C): p[k] = sum_j c[k][j] * x^j (Horner),
 * x = (T - t_mid_c) / t_half_range_c, T first clamped to t_min_c..t_max_c when clamp is 1. */
static inline void @parameters@(const @type@ *s, ACCELCAL_REAL temperature_c,
                                       ACCELCAL_REAL p[@N@])
{
    ACCELCAL_REAL t = temperature_c;
    if (s->clamp) {
        if (t < s->t_min_c) t = s->t_min_c;
        if (t > s->t_max_c) t = s->t_max_c;
    }
    const ACCELCAL_REAL x = (t - s->t_mid_c) / s->t_half_range_c;
    for (int k = 0; k < @N@; ++k) {
        ACCELCAL_REAL value = 0;
        for (int j = @DEGREE@; j >= 0; --j) value = value * x + s->coefficients[k][j];
        p[k] = value;
    }
}

/* Compensate one raw reading (@unit@, codes x @lsb@) taken at the sensor's temperature (deg C):
 * out = M * C * S * (raw - b), C lower unit-triangular (nonorth yx, zx, zy), S diagonal. */
static inline void @apply@(const @type@ *s, ACCELCAL_REAL temperature_c,
                                  const ACCELCAL_REAL raw[3], ACCELCAL_REAL out[3])
{
    ACCELCAL_REAL p[@N@], m[3][3];
    @parameters@(s, temperature_c, p);
    const ACCELCAL_REAL u0 = p[3] * (raw[0] - p[0]);
    const ACCELCAL_REAL u1 = p[4] * (raw[1] - p[1]);
    const ACCELCAL_REAL u2 = p[5] * (raw[2] - p[2]);
    const ACCELCAL_REAL c[3] = {u0, p[6] * u0 + u1, p[7] * u0 + p[8] * u1 + u2};
    accelcal_rotation(&p[9], m);
    for (int i = 0; i < 3; ++i) out[i] = m[i][0] * c[0] + m[i][1] * c[1] + m[i][2] * c[2];
}

/* As @apply@, from the part's signed codes at the calibrated range. */
static inline void @apply@_codes(const @type@ *s, ACCELCAL_REAL temperature_c,
                                        const int32_t codes[3], ACCELCAL_REAL out[3])
{
    const ACCELCAL_REAL raw[3] = {codes[0] * s->@lsb@, codes[1] * s->@lsb@, codes[2] * s->@lsb@};
    @apply@(s, temperature_c, raw, out);
}
"""


def eq1_c_export(token: str, unit: str, sensor: str, parameter_names: tuple[str, ...]) -> CExport:
    """The C header's section of an Eq. 1 quantity: `token` "" for the accelerometer (accelcal_sensor,
    accelcal_apply, ACCELCAL_SENSORS: the header's first names), else e.g. "mag" (accelcal_mag,
    accelcal_apply_mag, ACCELCAL_MAGS)."""
    if token:
        names = {"type": f"accelcal_{token}", "parameters": f"accelcal_{token}_parameters",
                 "apply": f"accelcal_apply_{token}", "table": f"ACCELCAL_{token.upper()}S",
                 "index": f"ACCELCAL_{token.upper()}_", "count": f"ACCELCAL_N_{token.upper()}S",
                 "N": f"ACCELCAL_{token.upper()}_N_PARAMETERS", "DEGREE": f"ACCELCAL_{token.upper()}_DEGREE"}
    else:
        names = {"type": "accelcal_sensor", "parameters": "accelcal_parameters", "apply": "accelcal_apply",
                 "table": "ACCELCAL_SENSORS", "index": "ACCELCAL_SENSOR_", "count": "ACCELCAL_N_SENSORS",
                 "N": "ACCELCAL_N_PARAMETERS", "DEGREE": "ACCELCAL_DEGREE"}
    lsb = f"lsb_{unit}"
    functions = _FUNCTIONS
    for key, value in {**names, "unit": unit, "lsb": lsb}.items():
        functions = functions.replace(f"@{key}@", value)
    return CExport(
        type_name=names["type"], table=names["table"], index=names["index"], count=names["count"],
        n_parameters=names["N"], degree=names["DEGREE"], lsb=lsb,
        comment=(f"Model ({sensor}s): paper Eq. 1, U_SF = M * C * S * (U - b); each parameter a polynomial of the "
                 "sensor's own", "temperature (Eq. 8). Parameter order: " + ", ".join(parameter_names) + ".",
                 f"Usage: {names['apply']}(&{names['table']}[{names['index']}<SERIAL>], temperature_c, raw, out);"),
        functions=functions, shared=(ROTATION, "ACCELCAL_ROTATION"))
