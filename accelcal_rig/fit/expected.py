"""The |g| RMSE a fit is expected to reach on the poses it was fitted to.

`noise_floor_mg` is the RMSE the true parameters would leave. A fit does better on its own poses: each
parameter it fits takes up part of the noise (a 9-parameter fit on 24 poses leaves about 21 % less in
RMS). With the fit's whitened Jacobian J at its solution the residuals are r = (I − H) ε, H the hat matrix
J (JᵀJ)⁻¹ Jᵀ, ε the whitened noise; each pose's |g| residual is its residual vector projected on its
direction. The expectation of its square, averaged over the poses, is the expected fit RMSE. The
turntable's pointing error turns gravity without changing its magnitude: it costs |g| nothing before the
fit, and only what the fit's mixing passes on after it.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.fit.lm import pointing_covariance_g2, reference_sigma_g


def expected_reference_rmse_mg(jacobian: np.ndarray, reference_g: np.ndarray, stderr_g: np.ndarray,
                               accuracy_rad: float) -> float:
    """Reference mode: `jacobian` (3N × p) of the residuals (reading − reference) / σ, pose by pose."""
    reference_g = np.asarray(reference_g, dtype=float)
    stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)
    n = len(reference_g)
    sigma_g = reference_sigma_g(stderr_g, reference_g, accuracy_rad)
    # The noise each pose's whitened residual carries: its samples' (diagonal) and a small rotation's.
    noise = np.einsum("na,ab->nab", stderr_g**2, np.eye(3)) + pointing_covariance_g2(reference_g, accuracy_rad)
    noise /= sigma_g[:, :, None] * sigma_g[:, None, :]
    # |g| residual = projection · whitened: the residual along the reference's direction (a unit vector: a
    # magnetometer's reference is half a gauss, not one).
    projection = reference_g / np.linalg.norm(reference_g, axis=1, keepdims=True) * sigma_g
    q, _ = np.linalg.qr(jacobian)
    q = q.reshape(n, 3, -1)                                         # each pose's rows of Q, H = Q Qᵀ
    # u = P (I − Q Qᵀ) ε with P one 3-block per pose and ε's covariance block-diagonal, so the diagonal of
    # its covariance is p Σ pᵀ − 2 (p Σ Q)·(p Q) + (p Q) (Qᵀ Σ Q) (p Q)ᵀ, pose by pose, without the 3N × 3N H.
    p_q = np.einsum("na,nap->np", projection, q)
    p_noise_q = np.einsum("na,nab,nbp->np", projection, noise, q)
    q_noise_q = np.einsum("nap,nab,nbr->pr", q, noise, q)
    variance = (np.einsum("na,nab,nb->n", projection, noise, projection) - 2.0 * np.sum(p_noise_q * p_q, axis=1)
                + np.einsum("np,pr,nr->n", p_q, q_noise_q, p_q))
    return float(np.sqrt(max(variance.mean(), 0.0)) * 1e3)


def expected_norm_rmse_mg(jacobian: np.ndarray, sigma_norm_g: np.ndarray) -> float:
    """Norm-only mode: `jacobian` (N × p) of the residuals (|reading| − 1) / σ_norm."""
    q, _ = np.linalg.qr(jacobian)
    leverage = np.sum(q**2, axis=1)
    # As many parameters as poses: every leverage is 1 and nothing is left (rounding may dip below zero).
    return float(np.sqrt(max(np.mean(np.asarray(sigma_norm_g) ** 2 * (1.0 - leverage)), 0.0)) * 1e3)


def thermal_jacobian(setpoint_jacobians: list[np.ndarray], powers: list[np.ndarray], per_pose_rows: int) -> np.ndarray:
    """The Jacobian of a thermal model's coefficients, from each setpoint fit's Jacobian in its parameters
    and the polynomial powers of each pose's scaled temperature: row block of pose i, column (parameter j,
    power m) = ∂r_i/∂θ_j · x_i^m."""
    blocks = []
    for jacobian, x_powers in zip(setpoint_jacobians, powers):
        n_poses = len(x_powers)
        per_pose = jacobian.reshape(n_poses, per_pose_rows, -1)                    # (n, rows, p)
        blocks.append(np.einsum("nrp,nm->nrpm", per_pose, x_powers).reshape(n_poses * per_pose_rows, -1))
    return np.vstack(blocks)
