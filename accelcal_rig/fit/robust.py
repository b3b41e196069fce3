"""Norm-only fits of real recordings whose intervals scatter more than their standard errors say.

A static interval's standard error counts only its own samples' noise; a real hand-held recording adds what
varies from one placement to the next (the hand, drift, 1/f noise, a not quite still sensor), so χ²_red
sits far above 1 and the longest interval, with the smallest standard error, dominates the fit. The excess
is modelled as one scatter floor τ shared by every interval, added in quadrature to each one's |g|
uncertainty and chosen so that χ²_red of the refit is 1 (the Paule–Mandel estimator of a between-interval
variance, iterated: each refit moves the residuals). When χ²_red is at most 1 already, the standard errors
explain the scatter and nothing changes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from accelcal_rig.fit.lm import FreeParameters, SfemFit, fit_sfem, norm_sigma
from accelcal_rig.fit.sfem import correct

#: Refits at most; the floor settles to 0.1 % within a few.
MAX_REFITS = 20


@dataclass(frozen=True)
class FloorFit:
    fit: SfemFit
    chi2_reduced_before: float    # with the intervals' standard errors alone
    scatter_floor_g: float        # 0 when they explain the scatter


def fit_norm_only_with_floor(mean_g: np.ndarray, stderr_g: np.ndarray, free: FreeParameters,
                             gravity_g: float = 1.0) -> FloorFit:
    fit = fit_sfem(mean_g, stderr_g, None, "norm-only", free, gravity_g=gravity_g)
    before = fit.chi2_reduced
    dof = len(mean_g) - int(fit.free.sum())
    if dof <= 0 or not before > 1.0:
        return FloorFit(fit, before, 0.0)
    own = norm_sigma(np.asarray(mean_g, dtype=float), np.maximum(np.asarray(stderr_g, dtype=float), 1e-9)) ** 2
    floor = 0.0
    for _ in range(MAX_REFITS):
        residual = (np.linalg.norm(correct(mean_g, fit.parameters), axis=1) - gravity_g) ** 2

        def excess(tau2: float, residual: np.ndarray = residual) -> float:
            return float(np.sum(residual / (own + tau2)) - dof)

        upper = float(residual.max()) * len(residual) + 1e-30
        updated = float(np.sqrt(brentq(excess, 0.0, upper))) if excess(0.0) > 0 else 0.0
        fit = fit_sfem(mean_g, stderr_g, None, "norm-only", free, gravity_g=gravity_g, scatter_floor_g=updated)
        if abs(updated - floor) <= 1e-3 * updated:
            floor = updated
            break
        floor = updated
    return FloorFit(fit, before, floor)
