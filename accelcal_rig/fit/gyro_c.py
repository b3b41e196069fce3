"""The rate-table gyroscope model in C for the C header (export/c_header.py): `accelcal_apply_gyro` inverts the
model exactly as `fit.gyro_model.correct_rate` does (Newton's method on each axis's scale curve, as many steps)."""

from __future__ import annotations

from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.channel_model import CExport

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


def gyro_c_export() -> CExport:
    """The C header's section of rate-table gyroscopes."""
    assert list(gyro_model.PARAMETER_NAMES[12:18]) == [f"{t}_{a}" for t in ("asymmetry", "nonlinearity")
                                                       for a in "xyz"]  # the offsets the C code uses
    return CExport(
        type_name="accelcal_gyro", table="ACCELCAL_GYROS", index="ACCELCAL_GYRO_", count="ACCELCAL_N_GYROS",
        n_parameters="ACCELCAL_GYRO_N_PARAMETERS", degree="ACCELCAL_GYRO_DEGREE", lsb="lsb_dps",
        comment=("Gyroscopes calibrated on a rate table (model gyro-rate-table, fit/gyro_model.py), per temperature:",
                 "raw = b + u + a|u| + n u (u/1000)^2 + G f, u = K w. Parameter order: "
                 + ", ".join(gyro_model.PARAMETER_NAMES) + ".",
                 "Usage: accelcal_apply_gyro(&ACCELCAL_GYROS[ACCELCAL_GYRO_<SERIAL>], temperature_c, raw_dps, force_g, "
                 "out_dps);"),
        functions=_GYRO_FUNCTIONS,
        defines=(("ACCELCAL_GYRO_NEWTON_STEPS", str(_GYRO_NEWTON_STEPS)),
                 ("ACCELCAL_GYRO_NONLINEARITY_RATE_DPS", repr(gyro_model.NONLINEARITY_RATE_DPS))))
