"""One DUT's uncertainty budget: what each source costs a compensated reading, per axis, at the calibration
temperatures and in the worst case over the calibrated range and every orientation; and, in a dry run,
how often the verification poses' errors against the simulation truth fall inside the expanded
uncertainty (it should be about 95 % at k = 2).

The reading the budget is stated for is one like a calibration pose: averaged over as many samples, its
temperature read as the poses' were (once at its start and once at its end).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
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
    model_variance,
    output_uncertainty,
    two_stage_map,
)
from accelcal_rig.store.read import VectorPoses

#: Orientations and temperatures the worst case is sought over.
BUDGET_ORIENTATIONS = 48
BUDGET_TEMPERATURES = 41


def fitted_powers(thermal: ThermalModel, n_setpoints: int, joint: bool) -> int:
    """Polynomial coefficients per parameter the fit determined (a two-stage fit lowers the degree to what
    its setpoints can fix; the joint fit refines every power)."""
    return thermal.coefficients.shape[1] if joint else min(thermal.degree, n_setpoints - 1) + 1


@dataclass(frozen=True)
class FittedTerms:
    """What a joint fit took off each calibration pose's reading beside Eq. 1 (fit_joint, `fit.hysteresis`):
    a bias of ±h by the direction the pose's temperature was approached from and one of c × its rate of
    temperature change."""

    approach: np.ndarray              # (N,) +1 warming, −1 cooling, of the calibration poses
    hysteresis_g: np.ndarray          # (3,) h per axis, g
    rate_c_per_min: np.ndarray        # (N,) each calibration pose's rate of temperature change
    rate_g: np.ndarray                # (3,) c per axis, g per °C/min

    def shift_g(self) -> np.ndarray:
        """(N, 3) what the terms add to each pose's reading."""
        return self.approach[:, None] * self.hysteresis_g + self.rate_c_per_min[:, None] * self.rate_g


def calibration_covariance(poses: VectorPoses, groups: list[np.ndarray], fits: list[SfemFit], thermal: ThermalModel,
                           temperatures: np.ndarray, pose_temperatures: np.ndarray, mode: FitMode,
                           joint: bool, terms: FittedTerms | None = None) -> CoefficientCovariance:
    """The coefficients' covariance by source, for the estimator the fit used.

    `terms`: what a joint fit took off the readings beside the thermal model (its hysteresis and rate). The
    residuals are then those of the fit as fitted (a term fitted is no scatter beyond the noise); the map to
    the coefficients is the fit's own, the terms' columns in it (estimating h and c beside the bias costs
    the bias what they share with it); and the hysteresis becomes a source (hysteresis_u_g).

    The thermal model's term of a joint fit (which has no per-setpoint estimates about a polynomial to
    check): each band's offset about the model, as a bias (band_misfit), where it is (model_variance), at
    the band's mean temperature. Its size comes from the calibration poses' own residuals. Readings taken
    while the temperature moves (its rate, a hysteresis swinging after a turn and relaxing) leave a misfit
    common to a band's poses, which χ² (`scatter_beyond_noise`) spreads over every pose as if it were
    independent from pose to pose, and so averages away. Not counted twice: `scatter_beyond_noise` is what
    that misfit costs the coefficients' estimate, `thermal_model` what it costs a reading the model does not
    describe (the two parts of a prediction's uncertainty); and the terms' own share is taken off first."""
    free = fits[0].free
    n_powers = fitted_powers(thermal, len(groups), joint)
    sigmas = np.array([f.sigma for f in fits])
    rows = np.concatenate(groups)
    per_pose_rows = 3 if mode == "reference" else 1
    shift = terms.shift_g() if terms is not None else np.zeros((len(poses.mean), 3))
    n_coefficients = int(np.sum(free)) * n_powers
    if joint:
        powers = [np.vander(thermal.scaled(pose_temperatures[g]), n_powers, increasing=True) for g in groups]
        jacobian = thermal_jacobian([f.jacobian for f in fits], powers, per_pose_rows)
        if terms is not None:  # a term shifts the reading as the bias does: its column is the bias's × its factor
            bias = np.vstack([f.jacobian[:, 0:3] for f in fits])
            jacobian = np.hstack([jacobian] + [np.repeat(factor[rows], per_pose_rows)[:, None] * bias
                                               for factor in (terms.approach, terms.rate_c_per_min)])
        mapping = joint_map(jacobian)
        residual_model = np.zeros((len(groups), 12))  # no per-setpoint estimates to compare: band_misfit
    else:
        mapping = two_stage_map([f.jacobian for f in fits], thermal.scaled(temperatures), sigmas, free, n_powers)
        residual_model = thermal.residuals if len(thermal.residuals) else np.zeros((0, 12))
    accuracy = np.radians(poses.reference_accuracy_arcsec / 3600)
    compensated = correct(poses.mean[rows] - shift[rows], thermal.parameters_at(pose_temperatures[rows], "extrapolate"))
    if mode == "reference":
        reference = poses.reference[rows]
        sigma = reference_sigma_g(np.maximum(poses.stderr[rows], 1e-9), reference, accuracy)
        residuals = ((compensated - reference) / sigma).ravel()
    else:
        reference = None
        residuals = (np.linalg.norm(compensated, axis=1) - poses.magnitude) / norm_sigma(poses.mean[rows],
                                                                                          poses.stderr[rows])
    found = coefficient_covariance(mapping, reference, poses.stderr[rows], accuracy, free, n_powers, residuals,
                                   residual_model, sigmas, temperatures)
    if joint:  # the bands' own biases about the model: the polynomial's and the terms' coefficients fitted per axis
        offsets, offset_sigma, left = band_misfit(residuals, jacobian, [f.jacobian[:, 0:3] for f in fits])
        bias = np.zeros(12, dtype=bool)
        bias[0:3] = True
        variance, local = model_variance(offsets, offset_sigma, bias, n_powers + (2 if terms is not None else 0),
                                         left)
        found = replace(found, model_variance=variance, model_temperatures_c=np.asarray(temperatures, dtype=float),
                        model_variance_by_temperature=local)
    if mapping.shape[0] == n_coefficients:
        return found
    coefficients = slice(0, n_coefficients)
    total = found.noise + found.pointing + found.excess
    h_variance = np.diagonal(total)[n_coefficients:n_coefficients + 3]
    assert terms is not None
    return replace(found, noise=found.noise[coefficients, coefficients],
                   pointing=found.pointing[coefficients, coefficients], excess=found.excess[coefficients, coefficients],
                   hysteresis=hysteresis_u_g(terms.hysteresis_g, h_variance))


def band_misfit(residuals: np.ndarray, jacobian: np.ndarray,
                bias_jacobians: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A joint fit's misfit common to a band's poses, as a bias: each band's whitened residuals (in the order
    of `bias_jacobians`, each band's rows of ∂residual/∂bias; `jacobian` the whole fit's) fitted by a bias
    of its own. (K, 12) each: the offsets δ on the bias parameters (zero on the others), their 1σ were they
    free, and the 1σ noise alone leaves in them after the fit (one on the others): model_variance's
    residuals, sigma and residual_sigma, as it takes the per-setpoint estimates about their polynomial."""
    q, _ = np.linalg.qr(jacobian)
    count = len(bias_jacobians)
    offsets, sigma, left = np.zeros((count, 12)), np.ones((count, 12)), np.ones((count, 12))
    start = 0
    for k, bias in enumerate(bias_jacobians):
        rows = slice(start, start + len(bias))
        start += len(bias)
        inverse = np.linalg.inv(bias.T @ bias)
        offsets[k, 0:3] = inverse @ bias.T @ residuals[rows]
        sigma[k, 0:3] = np.sqrt(np.diagonal(inverse))
        shared = q[rows].T @ bias                                  # what the fit's own coefficients take of it
        left[k, 0:3] = np.sqrt(np.maximum(np.diagonal(inverse @ (bias.T @ bias - shared.T @ shared) @ inverse), 0.0))
    return offsets, sigma, left


def hysteresis_u_g(h_g: np.ndarray, h_variance_g2: np.ndarray) -> np.ndarray:
    """(3,) The standard uncertainty of a reading's hysteresis, per axis, in g: a reading at rest after its
    temperature moved lies on one branch, ±h from the calibration (a bidirectional fit's, the mean of both
    branches), the side unknown to whoever applies it: a two-valued error of standard deviation h. With h
    known only as its estimate ĥ ± u(ĥ), the expectation of h² is ĥ² + u(ĥ)². A reading long at rest, its
    hysteresis relaxed, is nearer the middle: the term is then an upper bound."""
    return np.sqrt(np.asarray(h_g, dtype=float) ** 2 + np.maximum(np.asarray(h_variance_g2, dtype=float), 0.0))


def temperature_scatter_c(poses: VectorPoses, pose_temperatures: np.ndarray, n_groups: int) -> float:
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


def budget(poses: VectorPoses, covariance: CoefficientCovariance, thermal: ThermalModel, temperatures: np.ndarray,
           scatter_c: float, milli: str = "mg", size_source: str = "gravity") -> dict[str, Any]:
    """The budget of a reading like a calibration pose at each calibration temperature and the worst case
    over the range, per axis, in thousandths of the channel's unit (`milli`: mg for an accelerometer): each
    source's largest value over every orientation, and the combined."""
    grid = np.unique(np.concatenate([temperatures, np.linspace(*thermal.domain_c, BUDGET_TEMPERATURES)]))
    directions = fibonacci_sphere(BUDGET_ORIENTATIONS) * poses.magnitude
    t = np.repeat(grid, len(directions))
    raw = distort(np.tile(directions, (len(grid), 1)), thermal.parameters_at(t, "extrapolate"))
    reading = np.median(poses.stderr, axis=0)
    sources = output_uncertainty(raw, t, thermal, covariance, np.tile(reading, (len(t), 1)), np.full(len(t), scatter_c),
                                 poses.magnitude_u / poses.magnitude, size_source=size_source)
    standard = combined(sources)

    def worst(values: np.ndarray, at: np.ndarray) -> list[float]:
        return (values[at].reshape(-1, len(directions), 3).max(axis=1).max(axis=0) * 1e3).tolist()

    rows = []
    for temperature in temperatures:
        at = np.isclose(t, temperature)
        rows.append({"temperature_c": float(temperature), f"standard_{milli}": worst(standard, at),
                     f"expanded_{milli}": [COVERAGE_FACTOR * u for u in worst(standard, at)],
                     f"sources_{milli}": {name: worst(u, at) for name, u in sources.items()}})
    everywhere = np.ones(len(t), dtype=bool)
    per_temperature = standard.reshape(len(grid), len(directions), 3).max(axis=1)
    return {
        "coverage_factor": COVERAGE_FACTOR,
        "reading": f"a reading averaged like a calibration pose (standard error {', '.join(f'{r * 1e3:.4f}' for r in reading)} "
                   f"{milli} per axis), its temperature read like a pose's (±{scatter_c:.3f} °C)",
        f"reading_stderr_{milli}": (reading * 1e3).tolist(),
        "temperature_u_c": scatter_c,
        f"sources_{milli}": {name: worst(u, everywhere) for name, u in sources.items()},
        f"standard_{milli}": worst(standard, everywhere),
        f"expanded_{milli}": [COVERAGE_FACTOR * u for u in worst(standard, everywhere)],
        "worst_at_c": grid[np.argmax(per_temperature, axis=0)].tolist(),
        "by_temperature": rows,
        "not_included": not_included(poses, covariance),
    }


#: Poses whose temperature moved faster than this were taken on a ramp (the loosest shipped soak criterion,
#: fast-bidirectional-ramp's `max_rate_c_per_min`, lets a soaked DUT move this much).
MOVING_C_PER_MIN = 0.1


def not_included(poses: VectorPoses, covariance: CoefficientCovariance) -> dict[str, str]:
    """What the budget leaves out because this calibration cannot measure it, each with why: the
    hysteresis where no fit measured it; the bias by the rate of temperature change where the calibration
    poses were taken while it moved and no fit measured it."""
    if covariance.hysteresis is not None:
        return {}
    missing = {"hysteresis": "not measured: a calibration that approaches each temperature from one side "
                             "cannot tell it from the bias (a bidirectional ramp's fit measures it); a reading "
                             "at rest that came to its temperature from the other side may differ by as much "
                             "as the sensor's hysteresis"}
    rates = []
    for setpoint in dict.fromkeys(poses.setpoint_c.tolist()):
        group = poses.setpoint_c == setpoint
        if group.sum() >= 3 and np.ptp(poses.t_s[group]) > 0:
            rates.append(60.0 * np.polyfit(poses.t_s[group], poses.temperature_c[group], 1)[0])
    rate = float(np.median(np.abs(rates))) if rates else 0.0
    if rate > MOVING_C_PER_MIN:
        missing["rate_of_change"] = (
            f"not measured: the calibration poses were taken while the temperature moved ({rate:.2f} °C/min, "
            "median), and a bias per °C/min cannot be told from the bias at one rate (a bidirectional ramp's fit "
            "measures it); a reading at rest differs by it times that rate")
    return missing


def truth_errors(checks: VectorPoses, covariance: CoefficientCovariance, thermal: ThermalModel,
                 compensated_g: np.ndarray, temperature_c: np.ndarray, temperature_u_c: np.ndarray,
                 mode: FitMode, out_of_range: OutOfRange) -> tuple[np.ndarray, dict[str, np.ndarray]] | None:
    """Dry runs: each verification pose's axis errors (n, 3) in the channel's unit against the simulation truth,
    and the budget's sources of its standard uncertainty (output_uncertainty); None without a truth. The truth
    is what the true parameters, in the fit's gauge, make of the noiseless reading (the true reference itself
    in reference mode) where the campaign stored the true reference; else what they make of the reading
    itself (its noise then in neither)."""
    if checks.truth_parameters is None:
        return None
    truth = checks.truth_parameters
    gauge = norm_only_gauge(truth) if mode == "norm-only" else truth
    if checks.truth_reference is None:
        expected = correct(checks.mean, gauge)
        sources = output_uncertainty(checks.mean, temperature_c, thermal, covariance, np.zeros_like(checks.stderr),
                                     temperature_u_c, checks.magnitude_u / checks.magnitude, out_of_range)
        return compensated_g - expected, sources
    expected = correct(distort(checks.truth_reference, truth), gauge)
    sources = output_uncertainty(checks.mean, temperature_c, thermal, covariance, checks.stderr, temperature_u_c,
                                 checks.magnitude_u / checks.magnitude, out_of_range)
    return compensated_g - expected, sources


def truth_coverage(checks: VectorPoses, covariance: CoefficientCovariance, thermal: ThermalModel,
                   compensated_g: np.ndarray, temperature_c: np.ndarray, temperature_u_c: np.ndarray,
                   mode: FitMode, out_of_range: OutOfRange) -> float | None:
    """Dry runs: the fraction of verification-pose axis errors against the simulation truth (truth_errors)
    inside each pose's expanded uncertainty."""
    found = truth_errors(checks, covariance, thermal, compensated_g, temperature_c, temperature_u_c, mode,
                         out_of_range)
    if found is None:
        return None
    errors, sources = found
    return float(np.mean(np.abs(errors) <= COVERAGE_FACTOR * combined(sources)))
