"""The gyroscope's error model on a rate table, per temperature:

    ω_raw = b + u + a ⊙ |u| + n ⊙ u ⊙ (u / ω_n)² + G · f,    u = K · ω

ω is the true angular rate in the DUT frame (°/s), f the specific force it feels in standard g, ω_raw the
reading (codes × nominal LSB). The 27 parameters, in this order: bias b (°/s); the sensitivity matrix K, its
diagonal the scale factors and its six off-diagonal terms the cross-axis sensitivities (misalignment and
non-orthogonality together, rad); the ± asymmetry a (the scale for positive rates is (1 + a) times that for
negative ones' (1 − a)); the cubic scale nonlinearity n, the relative change of scale at ω_n = 1000 °/s; the
g-sensitivity G (°/s per g, 3 × 3).

Gauge: a rate table turned about each fixture axis in turn defines all nine entries of K relative to the
fixture frame (the fixture's faces as the table's axis realises them, the DUT's nominal mount taken out):
no rotation is left free, unlike an accelerometer's norm-only fit. Every function takes parameter arrays
shaped (..., 27) and vectors shaped (..., 3) and broadcasts over the leading axes.
"""

from __future__ import annotations

import numpy as np

AXES = "xyz"
#: (row, column) of K for each off-diagonal term, in the order of PARAMETER_NAMES.
CROSS_TERMS: tuple[tuple[int, int], ...] = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
PARAMETER_NAMES: tuple[str, ...] = (
    *(f"bias_{a}_dps" for a in AXES),
    *(f"scale_{a}" for a in AXES),
    *(f"cross_{AXES[i]}{AXES[j]}_rad" for i, j in CROSS_TERMS),
    *(f"asymmetry_{a}" for a in AXES),
    *(f"nonlinearity_{a}" for a in AXES),
    *(f"gsens_{a}{b}_dps_per_g" for a in AXES for b in AXES),
)
N_PARAMETERS = len(PARAMETER_NAMES)
BIAS, SCALE, CROSS, ASYMMETRY, NONLINEARITY, GSENS = (slice(0, 3), slice(3, 6), slice(6, 12), slice(12, 15),
                                                     slice(15, 18), slice(18, 27))
IDENTITY_PARAMETERS = np.zeros(N_PARAMETERS)
IDENTITY_PARAMETERS[SCALE] = 1.0
#: The rate at which the nonlinearity term is the relative change of scale it names.
NONLINEARITY_RATE_DPS = 1000.0
#: Newton steps inverting the per-axis scale curve: |a| and |n| of a percent converge in three.
_INVERSE_STEPS = 6


def sensitivity_matrix(params: np.ndarray) -> np.ndarray:
    """K (..., 3, 3): scale factors on the diagonal, cross-axis terms off it."""
    params = np.asarray(params, dtype=float)
    k = np.zeros(params.shape[:-1] + (3, 3))
    k[..., [0, 1, 2], [0, 1, 2]] = params[..., SCALE]
    for column, (i, j) in enumerate(CROSS_TERMS):
        k[..., i, j] = params[..., CROSS.start + column]
    return k


def gsensitivity_matrix(params: np.ndarray) -> np.ndarray:
    """G (..., 3, 3), °/s per g: row the gyro axis, column the axis of the specific force."""
    params = np.asarray(params, dtype=float)
    return params[..., GSENS].reshape(params.shape[:-1] + (3, 3))


def _scale_curve(u: np.ndarray, params: np.ndarray) -> np.ndarray:
    """u + a|u| + n u (u/ω_n)²: each axis's reading of its own sensed rate before bias and g-sensitivity."""
    return u + params[..., ASYMMETRY] * np.abs(u) + params[..., NONLINEARITY] * u * (u / NONLINEARITY_RATE_DPS) ** 2


def distort_rate(true_dps: np.ndarray, force_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """The model forward: what a gyroscope with `params` reads for the true rate and specific force."""
    params = np.asarray(params, dtype=float)
    u = np.einsum("...ij,...j->...i", sensitivity_matrix(params), np.asarray(true_dps, dtype=float))
    g_term = np.einsum("...ij,...j->...i", gsensitivity_matrix(params), np.asarray(force_g, dtype=float))
    return params[..., BIAS] + _scale_curve(u, params) + g_term


def correct_rate(raw_dps: np.ndarray, force_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """The model inverted: the true rate (DUT frame) from a reading and the specific force it was taken at.
    Bias and g-sensitivity come off, each axis's scale curve is inverted by Newton's method, then K."""
    params = np.asarray(params, dtype=float)
    g_term = np.einsum("...ij,...j->...i", gsensitivity_matrix(params), np.asarray(force_g, dtype=float))
    target = np.asarray(raw_dps, dtype=float) - params[..., BIAS] - g_term
    u = target.copy()
    for _ in range(_INVERSE_STEPS):
        slope = (1.0 + params[..., ASYMMETRY] * np.sign(u)
                 + 3.0 * params[..., NONLINEARITY] * (u / NONLINEARITY_RATE_DPS) ** 2)
        u = u - (_scale_curve(u, params) - target) / slope
    return np.linalg.solve(sensitivity_matrix(params), u[..., None])[..., 0]


def distort_jacobian(true_dps: np.ndarray, force_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """∂distort_rate/∂θ, shape (..., 3, 27): every term is linear in its parameters but the scale curve's
    slope, so the columns are exact products."""
    params = np.asarray(params, dtype=float)
    true_dps, force_g = np.asarray(true_dps, dtype=float), np.asarray(force_g, dtype=float)
    lead = np.broadcast_shapes(params.shape[:-1], true_dps.shape[:-1], force_g.shape[:-1])
    params = np.broadcast_to(params, lead + (N_PARAMETERS,))
    true_dps, force_g = np.broadcast_to(true_dps, lead + (3,)), np.broadcast_to(force_g, lead + (3,))
    u = np.einsum("...ij,...j->...i", sensitivity_matrix(params), true_dps)
    slope = (1.0 + params[..., ASYMMETRY] * np.sign(u)
             + 3.0 * params[..., NONLINEARITY] * (u / NONLINEARITY_RATE_DPS) ** 2)
    jacobian = np.zeros(lead + (3, N_PARAMETERS))
    rows = [0, 1, 2]
    jacobian[..., rows, [BIAS.start + r for r in rows]] = 1.0
    jacobian[..., rows, [SCALE.start + r for r in rows]] = slope * true_dps
    for column, (i, j) in enumerate(CROSS_TERMS):
        jacobian[..., i, CROSS.start + column] = slope[..., i] * true_dps[..., j]
    jacobian[..., rows, [ASYMMETRY.start + r for r in rows]] = np.abs(u)
    jacobian[..., rows, [NONLINEARITY.start + r for r in rows]] = u * (u / NONLINEARITY_RATE_DPS) ** 2
    for i in rows:
        jacobian[..., i, GSENS.start + 3 * i: GSENS.start + 3 * i + 3] = force_g
    return jacobian


def read_at_scale(params: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """The parameters of a gyroscope that reads `factor` (..., 3) × what `params` says, per axis: its bias, K's
    rows and G's rows scaled, the nonlinearity (relative to a rate of the scaled reading) divided by factor²."""
    params = np.array(params, dtype=float)
    factor = np.asarray(factor, dtype=float)
    params[..., BIAS] *= factor
    params[..., SCALE] *= factor
    for column, (i, _) in enumerate(CROSS_TERMS):
        params[..., CROSS.start + column] *= factor[..., i]
    params[..., NONLINEARITY] /= factor**2
    params[..., GSENS] *= np.repeat(factor, 3, axis=-1)
    return params
