"""The sensor-frame error model, paper Eq. 1:  U_SF = M · C · S · (U − b).

U is the raw reading in g (codes × nominal LSB), U_SF the true specific force in the DUT frame. The 12
parameters, in this order: bias b (g), diagonal scale S, lower-triangular non-orthogonality C (α_yx, α_zx,
α_zy, rad) and misalignment M (a small rotation, as a rotation vector in rad). Every function takes
parameter arrays shaped (..., 12) and vectors shaped (..., 3) and broadcasts over the leading axes.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

PARAMETER_NAMES: tuple[str, ...] = (
    "bias_x_g", "bias_y_g", "bias_z_g",
    "scale_x", "scale_y", "scale_z",
    "nonorth_yx_rad", "nonorth_zx_rad", "nonorth_zy_rad",
    "misalign_x_rad", "misalign_y_rad", "misalign_z_rad",
)

IDENTITY_PARAMETERS = np.array([0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0], dtype=float)
#: Step of the central differences of the misalignment rotation (correct_jacobian).
MISALIGNMENT_STEP_RAD = 1e-6


def error_matrix(params: np.ndarray) -> np.ndarray:
    """A = M · C · S for each parameter set, shape (..., 3, 3)."""
    params = np.asarray(params, dtype=float)
    misalign, nonorth, scale = _factors(params.reshape(-1, 12))
    return (misalign @ nonorth @ scale).reshape(params.shape[:-1] + (3, 3))


def _factors(flat: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, C and S (N, 3, 3 each) of parameter sets (N, 12)."""
    scale = np.zeros((flat.shape[0], 3, 3))
    scale[:, [0, 1, 2], [0, 1, 2]] = flat[:, 3:6]
    nonorth = np.broadcast_to(np.eye(3), scale.shape).copy()
    nonorth[:, 1, 0] = flat[:, 6]
    nonorth[:, 2, 0] = flat[:, 7]
    nonorth[:, 2, 1] = flat[:, 8]
    return Rotation.from_rotvec(flat[:, 9:12]).as_matrix(), nonorth, scale


def correct(raw_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """Eq. 1 forward: raw reading → compensated specific force in the DUT frame."""
    a = error_matrix(params)
    b = np.asarray(params, dtype=float)[..., 0:3]
    return np.einsum("...ij,...j->...i", a, np.asarray(raw_g, dtype=float) - b)


def correct_jacobian(raw_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """∂correct/∂θ, shape (..., 3, 12). Bias, scale and non-orthogonality enter A·(U − b) linearly, so their
    columns are exact products; the misalignment's are central differences of M alone (step
    MISALIGNMENT_STEP_RAD), which is what a rotation vector leaves no short closed form for."""
    params, raw_g = np.asarray(params, dtype=float), np.asarray(raw_g, dtype=float)
    lead = np.broadcast_shapes(params.shape[:-1], raw_g.shape[:-1])
    flat = np.array(np.broadcast_to(params, lead + (12,)).reshape(-1, 12))
    offset = np.broadcast_to(raw_g, lead + (3,)).reshape(-1, 3) - flat[:, 0:3]        # U − b
    misalign, nonorth, _ = _factors(flat)
    mc = misalign @ nonorth
    scaled = flat[:, 3:6] * offset                                                    # S·(U − b)
    jacobian = np.empty((len(flat), 3, 12))
    jacobian[:, :, 0:3] = -mc * flat[:, None, 3:6]                                    # −A, column by column
    jacobian[:, :, 3:6] = mc * offset[:, None, :]
    jacobian[:, :, 6] = misalign[:, :, 1] * scaled[:, 0:1]
    jacobian[:, :, 7] = misalign[:, :, 2] * scaled[:, 0:1]
    jacobian[:, :, 8] = misalign[:, :, 2] * scaled[:, 1:2]
    steps = np.eye(3) * MISALIGNMENT_STEP_RAD
    turned = [Rotation.from_rotvec((flat[:, None, 9:12] + sign * steps).reshape(-1, 3)).as_matrix().reshape(-1, 3, 3, 3)
              for sign in (1.0, -1.0)]
    by_rotation = (turned[0] - turned[1]) / (2.0 * MISALIGNMENT_STEP_RAD)              # (N, k, 3, 3)
    jacobian[:, :, 9:12] = np.einsum("nkij,nj->nik", by_rotation, np.einsum("nij,nj->ni", nonorth, scaled))
    return jacobian.reshape(lead + (3, 12))


def distort(true_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """Eq. 1 inverse: the raw reading a sensor with `params` gives for the true specific force."""
    a_inv = np.linalg.inv(error_matrix(params))
    b = np.asarray(params, dtype=float)[..., 0:3]
    return np.einsum("...ij,...j->...i", a_inv, np.asarray(true_g, dtype=float)) + b


def norm_only_gauge(params: np.ndarray) -> np.ndarray:
    """The parameters in the norm-only gauge that describe the same |U_SF| everywhere.

    |A·v| depends on A only through AᵀA, so the equivalent A' = C'·S' is the lower-triangular L with
    LᵀL = AᵀA and a positive diagonal (M' = identity). With J the reversal permutation, J·AᵀA·J = K·Kᵀ
    (Cholesky, K lower) gives L = J·Kᵀ·J. Bias is unchanged.
    """
    params = np.asarray(params, dtype=float)
    a = error_matrix(params)
    reverse = np.eye(3)[::-1]
    k = np.linalg.cholesky(reverse @ np.swapaxes(a, -1, -2) @ a @ reverse)
    lower = reverse @ np.swapaxes(k, -1, -2) @ reverse
    scale = np.diagonal(lower, axis1=-2, axis2=-1)
    gauged = np.array(params, copy=True)
    gauged[..., 3:6] = scale
    gauged[..., 6] = lower[..., 1, 0] / scale[..., 0]
    gauged[..., 7] = lower[..., 2, 0] / scale[..., 0]
    gauged[..., 8] = lower[..., 2, 1] / scale[..., 1]
    gauged[..., 9:12] = 0.0
    return gauged
