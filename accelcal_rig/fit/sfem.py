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


def error_matrix(params: np.ndarray) -> np.ndarray:
    """A = M · C · S for each parameter set, shape (..., 3, 3)."""
    params = np.asarray(params, dtype=float)
    lead = params.shape[:-1]
    flat = params.reshape(-1, 12)
    scale = np.zeros((flat.shape[0], 3, 3))
    scale[:, [0, 1, 2], [0, 1, 2]] = flat[:, 3:6]
    nonorth = np.broadcast_to(np.eye(3), scale.shape).copy()
    nonorth[:, 1, 0] = flat[:, 6]
    nonorth[:, 2, 0] = flat[:, 7]
    nonorth[:, 2, 1] = flat[:, 8]
    misalign = Rotation.from_rotvec(flat[:, 9:12]).as_matrix()
    return (misalign @ nonorth @ scale).reshape(lead + (3, 3))


def correct(raw_g: np.ndarray, params: np.ndarray) -> np.ndarray:
    """Eq. 1 forward: raw reading → compensated specific force in the DUT frame."""
    a = error_matrix(params)
    b = np.asarray(params, dtype=float)[..., 0:3]
    return np.einsum("...ij,...j->...i", a, np.asarray(raw_g, dtype=float) - b)


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
