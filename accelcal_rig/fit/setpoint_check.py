"""The early check's figures: every DUT against its own fit of one setpoint's poses, while the campaign can
still do something about it (a loose mount, a DUT mounted in another orientation, a dead axis show at the
first setpoint, not in the fit after the last).

The fit is Eq. 1 solved for the reading, affine: measured ≈ K · expected + b, with K any 3 × 3 matrix (the
inverse of M·C·S: scale, non-orthogonality and any rotation) and b the bias; in closed form, every DUT at
once. Three figures come of it:

- `residual_ratio`: √χ²_red of the fit, each residual in units of its pose's standard error combined with
  the table's stated pointing (as the fit weighs them): about 1 for a DUT that sits still, far above when
  the DUT moves between poses (a loose mount), which no fit absorbs.
- `direction_deg`: a fit absorbs a rotation into K, so the mount is judged from the data instead: the
  angle of the rotation that best takes each pose's expected unit direction (the configured mount) onto the
  measured, bias-removed one (Kabsch). A few tenths of a degree for a DUT as configured; 90° or 180° for
  one plugged in turned.
- `axis_gain`: each axis's response to specific force, the norm of its row of K (g per g): about 1 for a
  live axis whatever its orientation, about 0 for one whose reading does not follow the poses (a broken
  channel, a frozen one).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from accelcal_rig.fit.lm import reference_sigma_g

#: The affine fit's parameters per DUT: K (9) and b (3).
AFFINE_PARAMETERS = 12
#: The expected directions (with a constant) must span 3-D affine space this well, relative to their
#: largest singular value, for K and b to be determined: a tilt check's poses near level do not.
MIN_DESIGN_CONDITION = 0.05


@dataclass(frozen=True)
class SetpointFigures:
    """Per DUT (D,): the residual ratio, the mount's direction error (NaN where an axis is dead: its
    directions say nothing of the mount), and each axis's gain (D, 3)."""

    residual_ratio: np.ndarray
    direction_deg: np.ndarray
    axis_gain: np.ndarray


def design_determined(reference_g: np.ndarray) -> bool:
    """Whether the poses' expected specific forces (n, 3) determine K and b with degrees of freedom left."""
    reference_g = np.asarray(reference_g, dtype=float)
    if 3 * len(reference_g) <= AFFINE_PARAMETERS:
        return False
    design = np.column_stack([reference_g, np.ones(len(reference_g))])
    singular = np.linalg.svd(design, compute_uv=False)
    return bool(singular[-1] >= MIN_DESIGN_CONDITION * singular[0])


def setpoint_figures(mean_g: np.ndarray, stderr_g: np.ndarray, reference_g: np.ndarray,
                     accuracy_rad: float, dead_gain: float) -> SetpointFigures:
    """The figures of D DUTs at one setpoint: `mean_g`, `stderr_g`, `reference_g` (D, n, 3), each pose's
    mean, its standard error and what it should read through the DUT's configured mount; `accuracy_rad`
    the table's ± pointing; an axis below `dead_gain` is dead (its DUT's direction is then not judged).
    The design must be determined (`design_determined`)."""
    mean_g, reference_g = np.asarray(mean_g, dtype=float), np.asarray(reference_g, dtype=float)
    n_duts, n_poses, _ = mean_g.shape
    design = np.concatenate([reference_g, np.ones((n_duts, n_poses, 1))], axis=2)     # (D, n, 4)
    coefficients = np.linalg.pinv(design) @ mean_g                                     # (D, 4, 3)
    gain_matrix = np.swapaxes(coefficients[:, :3, :], 1, 2)                            # K: (D, 3, 3)
    bias_g = coefficients[:, 3, :]                                                     # (D, 3)
    residual_g = mean_g - design @ coefficients
    sigma_g = np.stack([reference_sigma_g(np.maximum(s, 1e-9), r, accuracy_rad)
                        for s, r in zip(np.asarray(stderr_g, dtype=float), reference_g)])
    dof = 3 * n_poses - AFFINE_PARAMETERS
    residual_ratio = np.sqrt(np.sum((residual_g / sigma_g) ** 2, axis=(1, 2)) / dof)
    axis_gain = np.linalg.norm(gain_matrix, axis=2)
    direction_deg = _mount_rotation_deg(mean_g - bias_g[:, None, :], reference_g)
    direction_deg[np.any(axis_gain < dead_gain, axis=1)] = np.nan
    return SetpointFigures(residual_ratio, direction_deg, axis_gain)


def _mount_rotation_deg(measured_g: np.ndarray, expected_g: np.ndarray) -> np.ndarray:
    """(D,): the angle of the rotation R that best takes the expected unit directions onto the measured ones
    (least squares over the poses: Kabsch, a proper rotation)."""
    measured = measured_g / np.linalg.norm(measured_g, axis=2, keepdims=True)
    expected = expected_g / np.linalg.norm(expected_g, axis=2, keepdims=True)
    covariance = np.einsum("dni,dnj->dij", measured, expected)                         # Σ u eᵀ
    u, _, vt = np.linalg.svd(covariance)
    sign = np.sign(np.linalg.det(u @ vt))
    correction = np.broadcast_to(np.eye(3), covariance.shape).copy()
    correction[:, 2, 2] = sign
    rotation = u @ correction @ vt                                                     # R e ≈ u
    cosine = np.clip((np.trace(rotation, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return np.degrees(np.arccos(cosine))
