"""One DUT's uncertainty budget: what each source costs a compensated reading, per axis, at the calibration
temperatures and in the worst case over the calibrated range and every orientation; and, in a dry run,
how often the verification poses' errors against the simulation truth fall inside the expanded
uncertainty (it should be about 95 % at k = 2).

The reading the budget is stated for is one like a calibration pose: averaged over as many samples, its
temperature read as the poses' were (once at its start and once at its end).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from accelcal_rig.core.geometry import fibonacci_sphere
from accelcal_rig.fit.expected import thermal_jacobian
from accelcal_rig.fit.lm import FitMode, SfemFit, norm_sigma, reference_sigma_g
from accelcal_rig.fit.sfem import correct, distort, norm_only_gauge
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel
from accelcal_rig.fit.uncertainty import (
    COVERAGE_FACTOR,
    CoefficientCovariance,
    coefficient_covariance,
    combined,
    joint_map,
    output_uncertainty,
    two_stage_map,
)
from accelcal_rig.store.read import DutPoses

#: Orientations and temperatures the worst case is sought over.
BUDGET_ORIENTATIONS = 48
BUDGET_TEMPERATURES = 41


def fitted_powers(thermal: ThermalModel, n_setpoints: int, joint: bool) -> int:
    """Polynomial coefficients per parameter the fit determined (a two-stage fit lowers the degree to what
    its setpoints can fix; the joint fit refines every power)."""
    return thermal.coefficients.shape[1] if joint else min(thermal.degree, n_setpoints - 1) + 1


def calibration_covariance(poses: DutPoses, groups: list[np.ndarray], fits: list[SfemFit], thermal: ThermalModel,
                           temperatures: np.ndarray, pose_temperatures: np.ndarray, mode: FitMode,
                           joint: bool) -> CoefficientCovariance:
    """The coefficients' covariance by source, for the estimator the fit used."""
    free = fits[0].free
    n_powers = fitted_powers(thermal, len(groups), joint)
    sigmas = np.array([f.sigma for f in fits])
    rows = np.concatenate(groups)
    if joint:
        powers = [np.vander(thermal.scaled(pose_temperatures[g]), n_powers, increasing=True) for g in groups]
        mapping = joint_map(thermal_jacobian([f.jacobian for f in fits], powers, 3 if mode == "reference" else 1))
    else:
        mapping = two_stage_map([f.jacobian for f in fits], thermal.scaled(temperatures), sigmas, free, n_powers)
    accuracy = np.radians(poses.reference_accuracy_arcsec / 3600)
    compensated = correct(poses.mean_g[rows], thermal.parameters_at(pose_temperatures[rows], "extrapolate"))
    if mode == "reference":
        reference = poses.reference_g[rows]
        sigma = reference_sigma_g(np.maximum(poses.stderr_g[rows], 1e-9), reference, accuracy)
        residuals = ((compensated - reference) / sigma).ravel()
    else:
        reference = None
        residuals = (np.linalg.norm(compensated, axis=1) - poses.gravity_g) / norm_sigma(poses.mean_g[rows],
                                                                                          poses.stderr_g[rows])
    residual_model = thermal.residuals if len(thermal.residuals) else np.zeros((0, 12))
    return coefficient_covariance(mapping, reference, poses.stderr_g[rows], accuracy, free, n_powers, residuals,
                                  residual_model, sigmas)


def temperature_scatter_c(poses: DutPoses, pose_temperatures: np.ndarray, n_groups: int) -> float:
    """The scatter of a pose's temperature reading about its setpoint's line in time: the uncertainty of a
    reading's temperature."""
    residual = poses.temperature_c - pose_temperatures
    dof = max(len(residual) - 2 * n_groups, 1)
    return float(np.sqrt(np.sum(residual**2) / dof))


def smoothed_temperature_u_c(t_s: np.ndarray, groups: list[np.ndarray], scatter_c: float) -> np.ndarray:
    """The uncertainty of each pose's temperature from its group's line in time (smoothed_temperatures)."""
    u = np.full(len(t_s), scatter_c)
    for group in groups:
        if len(group) >= 3 and np.ptp(t_s[group]) > 0:
            t = t_s[group]
            u[group] = scatter_c * np.sqrt(1.0 / len(t) + (t - t.mean()) ** 2 / np.sum((t - t.mean()) ** 2))
    return u


def budget(poses: DutPoses, covariance: CoefficientCovariance, thermal: ThermalModel, temperatures: np.ndarray,
           scatter_c: float) -> dict[str, Any]:
    """The budget of a reading like a calibration pose at each calibration temperature and the worst case
    over the range, per axis, in mg: each source's largest value over every orientation, and the combined."""
    grid = np.unique(np.concatenate([temperatures, np.linspace(*thermal.domain_c, BUDGET_TEMPERATURES)]))
    directions = fibonacci_sphere(BUDGET_ORIENTATIONS) * poses.gravity_g
    t = np.repeat(grid, len(directions))
    raw = distort(np.tile(directions, (len(grid), 1)), thermal.parameters_at(t, "extrapolate"))
    reading = np.median(poses.stderr_g, axis=0)
    sources = output_uncertainty(raw, t, thermal, covariance, np.tile(reading, (len(t), 1)), np.full(len(t), scatter_c),
                                 poses.gravity_uncertainty_g / poses.gravity_g)
    standard = combined(sources)

    def worst(values: np.ndarray, at: np.ndarray) -> list[float]:
        return (values[at].reshape(-1, len(directions), 3).max(axis=1).max(axis=0) * 1e3).tolist()

    rows = []
    for temperature in temperatures:
        at = np.isclose(t, temperature)
        rows.append({"temperature_c": float(temperature), "standard_mg": worst(standard, at),
                     "expanded_mg": [COVERAGE_FACTOR * u for u in worst(standard, at)],
                     "sources_mg": {name: worst(u, at) for name, u in sources.items()}})
    everywhere = np.ones(len(t), dtype=bool)
    per_temperature = standard.reshape(len(grid), len(directions), 3).max(axis=1)
    return {
        "coverage_factor": COVERAGE_FACTOR,
        "reading": f"a reading averaged like a calibration pose (standard error {', '.join(f'{r * 1e3:.4f}' for r in reading)} "
                   f"mg per axis), its temperature read like a pose's (±{scatter_c:.3f} °C)",
        "reading_stderr_mg": (reading * 1e3).tolist(),
        "temperature_u_c": scatter_c,
        "sources_mg": {name: worst(u, everywhere) for name, u in sources.items()},
        "standard_mg": worst(standard, everywhere),
        "expanded_mg": [COVERAGE_FACTOR * u for u in worst(standard, everywhere)],
        "worst_at_c": grid[np.argmax(per_temperature, axis=0)].tolist(),
        "by_temperature": rows,
    }


def truth_coverage(checks: DutPoses, covariance: CoefficientCovariance, thermal: ThermalModel,
                   compensated_g: np.ndarray, temperature_c: np.ndarray, temperature_u_c: np.ndarray,
                   mode: FitMode, out_of_range: OutOfRange) -> float | None:
    """Dry runs: the fraction of verification-pose axis errors against the simulation truth inside each pose's
    expanded uncertainty. The truth is what the true parameters, in the fit's gauge, make of the noiseless
    reading: the true gravity itself in reference mode."""
    if checks.truth_parameters is None or checks.truth_gravity_g is None:
        return None
    truth = checks.truth_parameters
    gauge = norm_only_gauge(truth) if mode == "norm-only" else truth
    expected = correct(distort(checks.truth_gravity_g, truth), gauge)
    sources = output_uncertainty(checks.mean_g, temperature_c, thermal, covariance, checks.stderr_g, temperature_u_c,
                                 checks.gravity_uncertainty_g / checks.gravity_g, out_of_range)
    inside = np.abs(compensated_g - expected) <= COVERAGE_FACTOR * combined(sources)
    return float(np.mean(inside))
