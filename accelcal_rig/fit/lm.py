"""Levenberg–Marquardt fit of the sensor-frame error model at one temperature (paper §3.1, Eq. 3–7).

Two modes. *reference*: the turntable's orientation gives the expected specific force of each pose,
and all 12 parameters are fitted. *norm-only*: only |U_SF| = 1 g is known (Eq. 3); a rotation of the
sensor frame is then invisible (the 24-pose design has Fisher rank 9 for the 12 parameters), so the
fit uses the paper's own gauge — C·S lower triangular, the sensor x axis as reference, M = identity —
and fits 9. Either mode can be restricted to bias and scale alone (6 parameters), for designs that
cannot see more (six positions). Residuals are weighted by each pose's standard error (W of Eq. 7),
combined in reference mode with the turntable's stated accuracy. The covariance is that of the stated
uncertainties; only when χ² exceeds its 99 % quantile (they are evidently too optimistic) is it scaled
by χ²_red, so unexplained scatter widens the 1σ instead of hiding.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import chi2

from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS, PARAMETER_NAMES, correct, correct_jacobian

FitMode = Literal["reference", "norm-only"]
FreeParameters = Literal["all", "bias-scale"]

#: Columns of the normalised weighted Jacobian whose smallest/largest singular value falls below this
#: are treated as not identified by the poses.
CONDITION_LIMIT = 1e-7


class DegenerateDesign(ValueError):
    """The poses cannot determine the requested parameters."""


def free_mask(mode: FitMode, free: FreeParameters = "all") -> np.ndarray:
    """Which of the 12 parameters a fit determines; the others stay at their identity values."""
    mask = np.ones(12, dtype=bool)
    if mode == "norm-only":
        mask[9:12] = False
    if free == "bias-scale":
        mask[6:12] = False
    return mask


@dataclass(frozen=True)
class SfemFit:
    """One temperature's fit. `sigma` is NaN for parameters the mode does not fit."""

    parameters: np.ndarray        # (12,)
    sigma: np.ndarray             # (12,) 1σ; scaled by √χ²_red when χ² exceeds its 99 % quantile
    free: np.ndarray              # (12,) bool
    chi2_reduced: float
    residuals: np.ndarray         # weighted residuals at the solution
    n_poses: int
    mode: FitMode
    jacobian: np.ndarray          # of the weighted residuals in the free parameters, at the solution

def pointing_covariance_g2(reference_g: np.ndarray, accuracy_rad: float) -> np.ndarray:
    """(n, 3, 3): a turntable uniform within ± `accuracy_rad` per axis turns the expected gravity g by a small
    rotation of variance a²/3 about each axis: covariance (a²/3)(|g|² I − g gᵀ), which changes no |g|."""
    reference_g = np.asarray(reference_g, dtype=float)
    squared = np.einsum("na,na->n", reference_g, reference_g)
    return accuracy_rad**2 / 3.0 * (squared[:, None, None] * np.eye(3) - np.einsum("na,nb->nab", reference_g, reference_g))


def reference_sigma_g(stderr_g: np.ndarray, reference_g: np.ndarray, accuracy_rad: float) -> np.ndarray:
    """(n, 3): each component's 1σ in reference mode, its samples' standard error and the table's pointing."""
    pointing = np.diagonal(pointing_covariance_g2(reference_g, accuracy_rad), axis1=1, axis2=2)
    return np.sqrt(np.asarray(stderr_g, dtype=float) ** 2 + pointing)


def norm_sigma(mean_g: np.ndarray, stderr_g: np.ndarray) -> np.ndarray:
    """Standard error of |U| per pose: each axis's error projected on the measured direction."""
    direction = mean_g / np.linalg.norm(mean_g, axis=1, keepdims=True)
    return np.sqrt(np.sum((direction * stderr_g) ** 2, axis=1))


def fit_sfem(mean_g: np.ndarray, stderr_g: np.ndarray, reference_g: np.ndarray | None, mode: FitMode,
             free: FreeParameters = "all", reference_accuracy_rad: float = 0.0, gravity_g: float = 1.0,
             scatter_floor_g: float = 0.0) -> SfemFit:
    """Fit Eq. 1 to per-pose means (n, 3) in g; `reference_g` (n, 3) is required in reference mode, and
    norm-only mode fits |U_SF| to `gravity_g`, the site's gravity in standard g. `scatter_floor_g`
    (norm-only): scatter between poses beyond their standard errors, added in quadrature to each pose's
    |g| uncertainty (fit/robust.py estimates it).

    `reference_accuracy_rad` is the turntable's ± accuracy per axis (uniform): the expected gravity then
    turns by a small random rotation of variance a²/3 about each direction, adding (a²/3)(1 − g_i²) to
    component i's variance.
    """
    mean_g = np.asarray(mean_g, dtype=float)
    stderr_g = np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)  # a noiseless pose must not divide by 0
    mask = free_mask(mode, free)
    n_free = int(mask.sum())
    n_poses = mean_g.shape[0]
    if mode == "reference":
        if reference_g is None:
            raise ValueError("reference mode needs the expected gravity of each pose")
        reference_g = np.asarray(reference_g, dtype=float)
        sigma_g = reference_sigma_g(stderr_g, reference_g, reference_accuracy_rad)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return ((correct(mean_g, _full(theta, mask)) - reference_g) / sigma_g).ravel()

        def derivatives(theta: np.ndarray) -> np.ndarray:
            return (correct_jacobian(mean_g, _full(theta, mask))[:, :, mask] / sigma_g[:, :, None]).reshape(-1, n_free)

        n_residuals = 3 * n_poses
    else:
        sigma_norm = np.sqrt(norm_sigma(mean_g, stderr_g) ** 2 + scatter_floor_g**2)

        def residuals(theta: np.ndarray) -> np.ndarray:
            return (np.linalg.norm(correct(mean_g, _full(theta, mask)), axis=1) - gravity_g) / sigma_norm

        def derivatives(theta: np.ndarray) -> np.ndarray:  # ∂|u|/∂θ = (u/|u|)·∂u/∂θ
            params = _full(theta, mask)
            output = correct(mean_g, params)
            unit = output / np.linalg.norm(output, axis=1, keepdims=True)
            return np.einsum("ni,nik->nk", unit, correct_jacobian(mean_g, params)[:, :, mask]) / sigma_norm[:, None]

        n_residuals = n_poses
    if n_residuals < n_free:
        raise DegenerateDesign(
            f"too few poses: {n_poses} poses give {n_residuals} equations for {n_free} parameters in {mode} mode"
        )
    result = least_squares(residuals, IDENTITY_PARAMETERS[mask], jac=derivatives, method="lm", xtol=1e-12, ftol=1e-12)
    jacobian = result.jac
    _check_identified(jacobian, mask, n_poses)
    dof = n_residuals - n_free
    chi2_reduced = float(result.fun @ result.fun / dof) if dof > 0 else float("nan")
    covariance = np.linalg.inv(jacobian.T @ jacobian)
    if dof > 0 and chi2_reduced > chi2.ppf(0.99, dof) / dof:
        covariance *= chi2_reduced  # the scatter exceeds what the stated uncertainties allow: widen, never hide
    sigma = np.full(12, np.nan)
    sigma[mask] = np.sqrt(np.diag(covariance))
    return SfemFit(_full(result.x, mask), sigma, mask, chi2_reduced, result.fun, n_poses, mode, jacobian)


def _full(theta: np.ndarray, mask: np.ndarray) -> np.ndarray:
    params = IDENTITY_PARAMETERS.copy()
    params[mask] = theta
    return params


def _check_identified(jacobian: np.ndarray, mask: np.ndarray, n_poses: int) -> None:
    """Refuse a fit whose poses leave some combination of parameters undetermined, naming it."""
    norms = np.linalg.norm(jacobian, axis=0)
    names = [n for n, free in zip(PARAMETER_NAMES, mask) if free]
    if np.any(norms == 0):
        blind = [n for n, norm in zip(names, norms) if norm == 0]
        raise DegenerateDesign(f"the {n_poses} poses do not constrain {', '.join(blind)}")
    _, singular, vt = np.linalg.svd(jacobian / norms, full_matrices=False)
    if singular[-1] < CONDITION_LIMIT * singular[0]:
        weakest = np.abs(vt[-1])
        involved = [names[i] for i in np.argsort(weakest)[::-1] if weakest[i] > 0.3]
        raise DegenerateDesign(
            f"the {n_poses} poses cannot separate {', '.join(involved)} (condition {singular[0] / singular[-1]:.1e}); "
            "spread the poses over more axes"
        )
