"""Fit a DUT's gyroscope from a campaign's rate steps and static poses: the rate-table model
(fit/gyro_model.py) by Levenberg–Marquardt at each setpoint, each parameter's polynomial over temperature,
the figures before and after, on the rate steps the fit never saw, and against the simulation's truth.

Each record's reference is the true angular rate in the DUT frame the rig recorded with it: the table's
commanded rate about the fixture axis and the Earth's rate as far as the rig config placed it (its vertical
component from `latitude_deg`, its horizontal one with `heading_deg`). The specific force each record was
taken at is the accelerometer channel's reference (gravity at the commanded pose): the g-sensitivity is fitted
against it. The table's rate accuracy is a systematic error of every rate: a common relative error of K,
stated beside each scale factor's 1σ, never a weight.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import yaml
from scipy.optimize import least_squares
from scipy.stats import chi2

from accelcal_rig.core.earth import EARTH_RATE_DPS
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.allan import FLICKER_FLOOR
from accelcal_rig.fit.calibration import ChannelCalibration, ChannelRangeScale, PolynomialModel, SetpointFit, plain
from accelcal_rig.fit.channel_model import ChannelFit
from accelcal_rig.fit.gyro_budget import combined, gyro_budget, sources_dps, truth_coverage
from accelcal_rig.fit.gyro_joint import fit_gyro_joint
from accelcal_rig.fit.parameter_uncertainty import certificate_temperatures, of_gyro
from accelcal_rig.fit.range_scale import RangeScale, RangeScaleError, fit_range_scales, to_own_range
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel, fit_thermal
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR, consistency
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import described_truth
from accelcal_rig.store.records import ChannelInfo

#: The calibration file's name of the model.
MODEL_ID = "gyro-rate-table"
#: The kinds of record the gyroscope fit uses: the static poses (bias, g-sensitivity) and the rate steps.
CALIBRATION_KINDS = ("pose", "rate")
VERIFICATION_KINDS = ("verify", "verify-rate")
#: A record's standard error is never taken below this (°/s): a block of identical codes is not exact.
STDERR_FLOOR_DPS = 1e-5
#: Normalised Jacobian columns whose smallest/largest singular value falls below this are not identified.
CONDITION_LIMIT = 1e-9


class GyroDesignError(ValueError):
    """The records cannot determine the gyroscope's model (no rate steps, too few axes)."""


@dataclass(frozen=True)
class GyroRecords:
    """One DUT's gyroscope records as arrays, row i of the campaign's stored poses."""

    serial: str
    info: ChannelInfo
    kind: np.ndarray                  # (N,) the plan's kind of each record
    setpoint_c: np.ndarray            # (N,)
    t_s: np.ndarray                   # (N,)
    temperature_c: np.ndarray         # (N,) the DUT's own sensor, mean of before and after
    mean_dps: np.ndarray              # (N, 3)
    stderr_dps: np.ndarray            # (N, 3)
    reference_dps: np.ndarray         # (N, 3) the true rate the rig recorded (table and Earth)
    force_g: np.ndarray               # (N, 3) the specific force (gravity at the commanded pose)
    truth_parameters: np.ndarray | None  # (N, 27) the simulation's, at each record's true temperature
    samples_per_record: int = 0       # samples averaged in each record (0: not known)
    range_dps: np.ndarray | None = None  # (N,) the ± full scale each record was taken at (None: all at info.range)
    #: The simulation's true sensitivity of each other range relative to the channel's: ε by range.
    truth_range_scale: dict[float, np.ndarray] | None = None

    def lsb_dps(self) -> np.ndarray:
        """(N, 1) each record's code size: the channel's, scaled by the record's range (codes of one width)."""
        ranges = np.full(len(self.kind), self.info.range) if self.range_dps is None else self.range_dps
        return np.asarray(self.info.lsb_at(ranges))[:, None]

    def rows(self, *kinds: str) -> np.ndarray:
        return np.isin(self.kind, kinds)


def read_gyro_records(campaign: Campaign, serial: str, channel: str, force_g: np.ndarray) -> GyroRecords:
    """The DUT's gyroscope channel over every stored record, with the specific force it felt at each (`force_g`,
    in standard g) beside it."""
    keys = campaign.pose_column("step_key")
    plan = campaign.header.plan
    kinds = dict(zip(plan.step_key, plan.kind))
    info = campaign.channel_info(serial, channel)
    return GyroRecords(
        serial=serial, info=info,
        kind=np.array([kinds.get(str(k), "") for k in keys]),
        setpoint_c=campaign.pose_column("setpoint_c"), t_s=campaign.pose_column("t_start_s"),
        temperature_c=campaign.dut_column(serial, "temperature_c").mean(axis=1),
        mean_dps=campaign.channel_column(serial, channel, "mean"),
        stderr_dps=campaign.channel_column(serial, channel, "stderr"),
        reference_dps=campaign.channel_column(serial, channel, "reference"),
        force_g=force_g,
        truth_parameters=_truth_at_own_range(campaign, serial, channel, info.range),
        samples_per_record=campaign.samples_per_pose,
        range_dps=campaign.channel_ranges(serial, channel),
        truth_range_scale=_truth_range_scale(campaign, serial, info.range),
    )


def _described_range_scale(campaign: Campaign, serial: str) -> dict[float, np.ndarray]:
    """The simulation's δ of each range (a gyroscope reads (1 + δ) × its truth there), where it describes them."""
    table = campaign.header.truth.get(serial, {}).get("gyro_range_scale")
    if table is None:
        return {}
    return {float(row[0]): np.asarray(row[1:4], dtype=float) for row in np.atleast_2d(np.asarray(table, dtype=float))}


def _truth_at_own_range(campaign: Campaign, serial: str, channel: str, own_range: float) -> np.ndarray | None:
    """The truth's parameters as the gyroscope reads at the channel's own range (the simulation describes them
    at its widest), each record's with the bias's wander over it where the campaign kept it: the part as it read
    then, so a check against the truth counts the wander a reading has, as the stated uncertainty does."""
    truth = described_truth(campaign, serial, channel)
    delta = _described_range_scale(campaign, serial).get(float(own_range))
    if truth is not None and delta is not None:
        truth = gyro_model.read_at_scale(truth, 1.0 + delta)
    wander = campaign.truth_column(serial, "gyro_wander_dps")
    if truth is not None and wander is not None and np.isfinite(wander).all():
        truth = np.array(truth, dtype=float)
        truth[:, gyro_model.BIAS] += wander
    return truth


def _truth_range_scale(campaign: Campaign, serial: str, own_range: float) -> dict[float, np.ndarray] | None:
    """The true ε of every range relative to the channel's own, where the simulation describes them."""
    described = _described_range_scale(campaign, serial)
    if float(own_range) not in described:
        return None
    own = 1.0 + described[float(own_range)]
    return {r: (1.0 + d) / own - 1.0 for r, d in described.items()}


@dataclass(frozen=True)
class GyroSetpointFit:
    parameters: np.ndarray            # (27,)
    sigma: np.ndarray                 # (27,) 1σ, widened by √χ²_red when χ² exceeds its 99 % quantile
    chi2_reduced: float
    n_records: int
    covariance: np.ndarray            # (27, 27), widened as sigma


def fit_gyro_setpoint(mean_dps: np.ndarray, stderr_dps: np.ndarray, reference_dps: np.ndarray,
                      force_g: np.ndarray) -> GyroSetpointFit:
    """The model at one temperature: readings (n, 3) against the true rates and specific forces, each weighted
    by its standard error. Refused (GyroDesignError) when the records leave a parameter undetermined."""
    sigma = np.maximum(np.asarray(stderr_dps, dtype=float), STDERR_FLOOR_DPS)
    n = len(mean_dps)
    if 3 * n <= gyro_model.N_PARAMETERS:
        raise GyroDesignError(f"{n} records give {3 * n} equations for {gyro_model.N_PARAMETERS} parameters")

    def residuals(theta: np.ndarray) -> np.ndarray:
        return ((gyro_model.distort_rate(reference_dps, force_g, theta) - mean_dps) / sigma).ravel()

    def derivatives(theta: np.ndarray) -> np.ndarray:
        jacobian = gyro_model.distort_jacobian(reference_dps, force_g, theta)
        return (jacobian / sigma[:, :, None]).reshape(-1, gyro_model.N_PARAMETERS)

    start = gyro_model.IDENTITY_PARAMETERS.copy()
    result = least_squares(residuals, start, jac=derivatives, method="lm", xtol=1e-12, ftol=1e-12)
    jacobian = result.jac
    _check_identified(jacobian, n)
    dof = 3 * n - gyro_model.N_PARAMETERS
    chi2_reduced = float(result.fun @ result.fun / dof)
    covariance = np.linalg.inv(jacobian.T @ jacobian)
    if chi2_reduced > chi2.ppf(0.99, dof) / dof:
        covariance *= chi2_reduced  # more scatter than the standard errors allow: widen, never hide
    return GyroSetpointFit(result.x, np.sqrt(np.diag(covariance)), chi2_reduced, n, covariance)


def _check_identified(jacobian: np.ndarray, n_records: int) -> None:
    norms = np.linalg.norm(jacobian, axis=0)
    blind = [name for name, norm in zip(gyro_model.PARAMETER_NAMES, norms) if norm == 0]
    if blind:
        raise GyroDesignError(f"the {n_records} records do not constrain {', '.join(blind)}: rate steps about each "
                              "axis in both directions at two or more rates, and static poses over the sphere")
    _, singular, vt = np.linalg.svd(jacobian / norms, full_matrices=False)
    if singular[-1] < CONDITION_LIMIT * singular[0]:
        weakest = np.abs(vt[-1])
        involved = [gyro_model.PARAMETER_NAMES[i] for i in np.argsort(weakest)[::-1] if weakest[i] > 0.3]
        raise GyroDesignError(f"the {n_records} records cannot separate {', '.join(involved)}")


def site_of(campaign: Campaign) -> dict[str, Any]:
    """The rig config's latitude, heading and table rate accuracy as the campaign recorded its rig."""
    try:
        rig = yaml.safe_load(campaign.header.rig_yaml) or {}
    except yaml.YAMLError:
        rig = {}
    turntable = rig.get("turntable") or {}
    return {"latitude_deg": rig.get("latitude_deg"), "heading_deg": rig.get("heading_deg"),
            "rate_accuracy_pct": float(turntable.get("rate_accuracy_pct") or 0.0),
            "accuracy_arcsec": float(campaign.header.turntable_accuracy_arcsec)}


def earth_rate_statement(site: dict[str, Any]) -> str:
    if site["latitude_deg"] is None:
        return ("not taken out: the rig config states no latitude_deg, so the Earth's rate (up to 0.0042 °/s) "
                "is left in the fitted bias")
    if site["heading_deg"] is None:
        return (f"vertical component at latitude {site['latitude_deg']:g}° taken out; the horizontal one "
                "(cos(latitude) × 0.0042 °/s) is left in the fitted bias: the rig config states no heading_deg")
    return (f"taken out at latitude {site['latitude_deg']:g}° and table heading {site['heading_deg']:g}° (its "
            "vertical component exactly; the horizontal one at rate steps averaged over each block's turn)")


GAUGE = ("the fixture frame as the rate table realises it: turning about each fixture axis defines all nine "
         "entries of K (scale on the diagonal, cross-axis terms off it), the DUT's nominal mount taken out")


def fit_gyro(records: GyroRecords, degree: int, out_of_range: OutOfRange, site: dict[str, Any],
             allan: dict[str, Any] | None = None, joint: bool = False) -> ChannelFit:
    """Fit each setpoint, the polynomials over temperature, and the figures of the calibration. `allan`: the
    noise record's figures (fit/noise_record.py), whose bias instability bounds how well a bias holds. `joint`
    (`fit.temperature_model: joint`, the ramp method): the polynomials then refined against every record at its
    own temperature (fit/gyro_joint.py); the per-setpoint fits still give the uncertainty budget its parts."""
    calibrating = records.rows(*CALIBRATION_KINDS)
    if not records.rows("rate").any():
        raise GyroDesignError(f"sensor {records.serial}: no rate steps stored, the gyroscope cannot be calibrated")
    scales: list[RangeScale] = []
    if records.range_dps is not None and np.any(records.range_dps != records.info.range):
        try:
            scales = fit_range_scales(records.mean_dps[calibrating], records.stderr_dps[calibrating],
                                      records.reference_dps[calibrating], records.force_g[calibrating],
                                      records.range_dps[calibrating], records.setpoint_c[calibrating],
                                      records.info.range, STDERR_FLOOR_DPS)
        except RangeScaleError as exc:
            raise GyroDesignError(f"sensor {records.serial} gyroscope: {exc}") from None
        mean, stderr = to_own_range(records.mean_dps, records.stderr_dps, records.range_dps, scales)
        records = replace(records, mean_dps=mean, stderr_dps=stderr)
    fits, kept, skipped = [], [], []
    for setpoint in dict.fromkeys(records.setpoint_c[calibrating].tolist()):
        group = np.flatnonzero(calibrating & (records.setpoint_c == setpoint))
        try:
            fits.append(fit_gyro_setpoint(records.mean_dps[group], records.stderr_dps[group],
                                          records.reference_dps[group], records.force_g[group]))
            kept.append((setpoint, group))
        except (GyroDesignError, np.linalg.LinAlgError) as exc:
            skipped.append(f"{setpoint:g} °C: {exc}")
    if not fits:
        raise GyroDesignError(f"sensor {records.serial} gyroscope: no setpoint's records determine it "
                              f"({'; '.join(skipped)})")
    setpoints = np.array([s for s, _ in kept])
    groups = [g for _, g in kept]
    temperatures = np.array([records.temperature_c[g].mean() for g in groups])
    estimates, sigmas = np.array([f.parameters for f in fits]), np.array([f.sigma for f in fits])
    thermal = fit_thermal(temperatures, estimates, sigmas, np.ones(gyro_model.N_PARAMETERS, dtype=bool), degree)
    joint_rows: np.ndarray | None = None
    if joint:
        rows = np.concatenate(groups)
        refined = fit_gyro_joint(thermal, records.temperature_c[rows], records.mean_dps[rows],
                                 records.stderr_dps[rows], records.reference_dps[rows], records.force_g[rows],
                                 STDERR_FLOOR_DPS)
        thermal = replace(refined, residuals=estimates - refined.parameters_at(temperatures, "extrapolate"))
        joint_rows = rows
    # A setpoint whose records do not determine the model (a campaign stopped in its rate steps) is left out,
    # said so: the others still calibrate the gyroscope over their range.
    thermal.warnings.extend(f"gyroscope setpoint left out: {why}" for why in skipped)
    metrics = _figures(records, thermal, out_of_range, calibrating)
    if scales:
        metrics["range_scales"] = _range_scale_figures(records, scales)
    metrics["chi2_reduced"] = [f.chi2_reduced for f in fits]
    metrics["temperature_range_c"] = [float(temperatures.min()), float(temperatures.max())]
    metrics["earth_rate"] = earth_rate_statement(site)
    wander = np.maximum(_bias_wander_dps(allan), wander_seen_dps(records, thermal, np.concatenate(groups), site))
    misfit = None if joint_rows is None else joint_misfit_dps(records, thermal, joint_rows, wander, site)
    systematic: dict[str, Any] = {**_systematic_sigma(site), "bias_instability_dps": wander, "model_misfit_dps": misfit}
    metrics["table_systematics_1sigma"] = {"scale_relative": systematic["scale"], "cross_rad": systematic["cross"],
                                           "earth_dps": systematic["earth_dps"]}
    metrics["bias_instability_1sigma_dps"] = (wander.tolist() if allan is not None
                                              else "not measured: the campaign has no noise record")
    covariances = np.array([f.covariance for f in fits])
    if "verification" in metrics:
        compensated = gyro_model.correct_rate(records.mean_dps, records.force_g,
                                              thermal.parameters_at(records.temperature_c, out_of_range))
        scale = _scale_error_ppm(records, compensated, records.rows("verify-rate"))
        metrics["verification"]["expanded_u"] = verification_uncertainty(records, compensated, systematic,
                                                                         None if scale is None else scale[1])
    parameter_u = of_gyro(thermal, temperatures, covariances, sigmas, systematic)
    metrics["parameter_uncertainty"] = parameter_u.expanded_table(certificate_temperatures(thermal.domain_c),
                                                                  list(gyro_model.PARAMETER_NAMES))
    temperature_u_c = _temperature_scatter_c(records, groups)
    largest = float(np.max(np.abs(records.reference_dps[records.rows("rate")])))
    metrics["uncertainty_budget"] = gyro_budget(thermal, temperatures, covariances, sigmas, temperature_u_c,
                                                systematic, round(largest))
    metrics["expanded_uncertainty_dps"] = metrics["uncertainty_budget"]["at_largest_rate"]["expanded_dps"]
    steps = records.rows("verify-rate")
    if steps.any():
        # What the verification rate steps' RMS error would be if the model were right: each reading's noise and
        # its mean's quantisation, the bias's wander at the step (the sensor's bias instability, its Allan floor:
        # a noise of the part as much as its white noise), the step's reference (the table's pointing, set anew
        # at each setpoint; its rate accuracy is common to calibration and checks, which the fitted scale takes
        # in), and the fit's noise carried to the step's rate, force and temperature — as the accelerometer's.
        fit_u = sources_dps(records.reference_dps[steps], records.force_g[steps], records.temperature_c[steps],
                            thermal, temperatures, covariances, sigmas, temperature_u_c, systematic,
                            out_of_range)["fit"]
        reference_u = measurement_sigma_dps(records, {**systematic, "scale": 0.0})[steps]
        wander_u = np.broadcast_to(np.asarray(wander, dtype=float), reference_u.shape)
        metrics["expected_fit_rmse_dps"] = float(np.sqrt(np.mean(reference_u**2 + wander_u**2 + fit_u**2)))
        if "verification" in metrics:  # the yardstick of its RMSE, under the name every vector channel's has
            metrics["verification"]["expected_rmse_dps"] = metrics["expected_fit_rmse_dps"]
    checks = records.rows(*VERIFICATION_KINDS)
    if checks.any():
        compensated = gyro_model.correct_rate(records.mean_dps, records.force_g,
                                              thermal.parameters_at(records.temperature_c, out_of_range))
        calibration_u = combined(sources_dps(records.reference_dps[checks], records.force_g[checks],
                                             records.temperature_c[checks], thermal, temperatures, covariances, sigmas,
                                             temperature_u_c, systematic, out_of_range))
        metrics["verification"]["consistency_k2"] = consistency(
            compensated[checks] - records.reference_dps[checks], calibration_u,
            measurement_sigma_dps(records, systematic)[checks])
    if records.truth_parameters is not None:
        metrics["truth_error"] = _truth_error(records, setpoints, groups, fits, systematic)
        checks = records.rows(*VERIFICATION_KINDS)
        if checks.any():
            metrics["truth_coverage_k2"] = truth_coverage(
                records.mean_dps[checks], records.force_g[checks], records.reference_dps[checks],
                records.temperature_c[checks], records.truth_parameters[checks], thermal, temperatures, covariances,
                sigmas, temperature_u_c, systematic, out_of_range)
    calibration = ChannelCalibration(
        model=MODEL_ID, quantity=records.info.quantity, unit=records.info.unit, serial=records.serial,
        mode="rate-table", free_parameters=list(gyro_model.PARAMETER_NAMES), range=records.info.range,
        lsb=records.info.lsb, validity_c=thermal.domain_c, out_of_range=out_of_range,
        polynomial=PolynomialModel(domain_c=thermal.domain_c, degree=degree,
                                   coefficients={n: plain(c) for n, c in
                                                 zip(gyro_model.PARAMETER_NAMES, thermal.coefficients)}),
        setpoints=[SetpointFit(setpoint_c=float(s), temperature_c=float(t), n_poses=f.n_records,
                               chi2_reduced=plain(f.chi2_reduced),
                               parameters=dict(zip(gyro_model.PARAMETER_NAMES, plain(f.parameters))),
                               sigma=dict(zip(gyro_model.PARAMETER_NAMES, plain(f.sigma))))
                   for s, t, f in zip(setpoints, temperatures, fits)],
        statements={"earth_rate": metrics["earth_rate"], "gauge": GAUGE,
                    **({"ranges": range_statement(records.info.range, scales)} if scales else {})},
        range_scales=[ChannelRangeScale(range=s.range, scale=plain(s.scale), sigma=plain(s.sigma)) for s in scales],
        metrics={k: plain(v) for k, v in metrics.items() if k != "truth_error"}, warnings=thermal.warnings,
    )
    return ChannelFit(records.serial, calibration, plain(metrics), thermal, parameter_u)


def range_statement(own_range: float, scales: list[RangeScale]) -> str:
    """What the certificate and the file say of the ranges the gyroscope was measured at."""
    others = "; ".join(f"±{s.range:g} °/s reads {', '.join(f'{v:.5f}' for v in s.scale)} × (x, y, z; 1σ "
                       f"{max(s.sigma):.1g}), fitted at {s.setpoints} setpoint{'s' if s.setpoints != 1 else ''}"
                       for s in scales)
    return (f"the model is the gyroscope's at ±{own_range:g} °/s, where its high rates were measured; readings at "
            f"rest and at low rates were taken at a finer range, each range's sensitivity relative to it constant "
            f"over temperature: {others}")


def _range_scale_figures(records: GyroRecords, scales: list[RangeScale]) -> dict[str, Any]:
    """Each other range's fitted scale, its 1σ and, in a dry run, its error against the simulation's truth."""
    figures: dict[str, Any] = {}
    for scale in scales:
        entry: dict[str, Any] = {"scale": scale.scale, "sigma": scale.sigma, "setpoints": scale.setpoints,
                                 "chi2_reduced": scale.chi2_reduced}
        true = (records.truth_range_scale or {}).get(scale.range)
        if true is not None:
            entry["truth_error"] = scale.scale - (1.0 + true)
        figures[f"{scale.range:g}"] = entry
    return figures


def _figures(records: GyroRecords, thermal: ThermalModel, out_of_range: OutOfRange,
             calibrating: np.ndarray) -> dict[str, Any]:
    """RMS error of the rate steps against their references before (raw) and after compensation, in-sample and
    on the verification records, and the bias left at rest."""
    compensated = gyro_model.correct_rate(records.mean_dps, records.force_g,
                                          thermal.parameters_at(records.temperature_c, out_of_range))
    before, after = records.mean_dps - records.reference_dps, compensated - records.reference_dps
    turning = records.rows("rate")
    figures: dict[str, Any] = {
        "rmse_before_dps": _rms(before[turning]), "rmse_after_dps": _rms(after[turning]),
        "rest_error_before_dps": _rms(before[records.rows("pose")]),
        "rest_error_after_dps": _rms(after[records.rows("pose")]),
        "noise_floor_dps": _rms(records.stderr_dps[calibrating]),
    }
    checks = records.rows("verify-rate")
    if checks.any() or records.rows("verify").any():
        rest = records.rows("verify")
        scale = _scale_error_ppm(records, compensated, checks)
        figures["verification"] = {
            "rate_steps": int(checks.sum()), "rmse_before_dps": _rms(before[checks]),
            "rmse_dps": _rms(after[checks]), "max_axis_error_dps": _max(after[checks]),
            "scale_error_ppm": None if scale is None else scale[0],
            "rest_error_dps": _rms(after[rest]), "noise_floor_dps": _rms(records.stderr_dps[checks | rest]),
            "temperatures_c": sorted({round(float(t), 2) for t in records.setpoint_c[checks | rest]}),
        }
    return figures


def _scale_error_ppm(records: GyroRecords, compensated: np.ndarray, rows: np.ndarray) -> tuple[float, float] | None:
    """The largest scale error at the verification rates, ppm, and its pair's noise (1σ, ppm): of each pair of
    steps turned both ways at one rate about one axis at one setpoint, the compensated difference along the
    turning axis over the reference's (a bias left over cancels in it, as it would not in one step's ratio
    at a low rate)."""
    if not rows.any():
        return None
    index = np.flatnonzero(rows)
    along = np.argmax(np.abs(records.reference_dps[index]), axis=1)
    reference = records.reference_dps[index, along]
    measured = compensated[index, along]
    noise = records.stderr_dps[index, along]
    errors, noises = [], []
    for i in range(len(index)):
        for j in range(len(index)):
            if (reference[i] > 0 > reference[j] and along[i] == along[j]
                    and records.setpoint_c[index[i]] == records.setpoint_c[index[j]]
                    and abs(reference[i] + reference[j]) < 1e-3 * abs(reference[i])):
                errors.append((measured[i] - measured[j]) / (reference[i] - reference[j]) - 1.0)
                noises.append(np.hypot(noise[i], noise[j]) / (reference[i] - reference[j]))
    if not errors:
        return None
    worst = int(np.argmax(np.abs(errors)))
    return float(1e6 * abs(errors[worst])), float(1e6 * noises[worst])


def verification_uncertainty(records: GyroRecords, compensated: np.ndarray, systematic: dict[str, Any],
                             scale_noise_ppm: float | None) -> dict[str, Any]:
    """U (k = 2) of each verification figure as a measurement of the compensated gyroscope's error: the
    reading's noise and the reference's errors — the table's rate accuracy along the turning axis, its
    pointing across it, the Earth's rate where the rig does not place it (the calibration's own uncertainty
    is what the figure measures). A root mean square is known to the root mean square of its terms'
    uncertainties, a largest value to its record's."""
    reference = records.reference_dps
    u = measurement_sigma_dps(records, systematic)
    steps, rest = records.rows("verify-rate"), records.rows("verify")
    out: dict[str, Any] = {"coverage_factor": COVERAGE_FACTOR}
    if steps.any():
        error = np.abs(compensated[steps] - reference[steps])
        out["rmse_dps"] = COVERAGE_FACTOR * float(np.sqrt(np.mean(u[steps] ** 2)))
        out["max_axis_error_dps"] = COVERAGE_FACTOR * float(u[steps].ravel()[np.argmax(error)])
    if scale_noise_ppm is not None:
        out["scale_error_ppm"] = COVERAGE_FACTOR * float(np.hypot(1e6 * systematic["scale"], scale_noise_ppm))
    if rest.any():
        out["rest_error_dps"] = COVERAGE_FACTOR * float(np.sqrt(np.mean(u[rest] ** 2)))
    return out


def measurement_sigma_dps(records: GyroRecords, systematic: dict[str, Any]) -> np.ndarray:
    """(N, 3) each record's standard uncertainty as a measurement of the compensated gyroscope's error: its
    reading's noise, its mean's quantisation, the table's rate accuracy along the turning axis and its pointing
    across it, the Earth's rate where the rig does not place it."""
    reference = records.reference_dps
    magnitude2 = np.sum(reference**2, axis=1, keepdims=True)
    return np.sqrt(records.stderr_dps**2 + quantisation_sigma(records) ** 2 + (reference * systematic["scale"]) ** 2
                   + (magnitude2 - reference**2) * systematic["cross"] ** 2 + systematic["earth_dps"] ** 2)


def quantisation_sigma(records: GyroRecords) -> np.ndarray:
    """(N, 3) what rounding to whole codes leaves in a record's mean, which its scatter does not show: a mean of
    codes whose noise is under a code is off the true mean by a periodic error of the signal's place between two
    codes, amplitude (LSB/π)·exp(−2π²σ²/LSB²) (the first term of its Fourier series for Gaussian noise σ; Widrow
    and Kollár, "Quantization Noise", 2008, ch. 7), its RMS over the place amplitude/√2. An ICM-42688-P's
    gyroscope at ±2000 °/s (noise 0.3 code) leaves about 0.0026 °/s; at ±250 °/s (2.3 codes), nothing."""
    lsb = records.lsb_dps()
    if records.samples_per_record < 2 or records.info.lsb <= 0:
        return np.zeros_like(records.stderr_dps)
    sigma = records.stderr_dps * np.sqrt(records.samples_per_record)  # each sample's noise
    return lsb / np.pi * np.exp(-2.0 * np.pi**2 * (sigma / lsb) ** 2) / np.sqrt(2.0)


def _rms(values: np.ndarray) -> float | None:
    return float(np.sqrt(np.mean(values**2))) if values.size else None


def _max(values: np.ndarray) -> float | None:
    return float(np.max(np.abs(values))) if values.size else None


#: The calibration records slow enough that the table's pointing and rate errors are under the noise in them
#: (3″ across 60 °/s is 0.0009 °/s): their scatter about a joint fit is the bias's own wander.
SLOW_RATE_DPS = 60.0


def wander_seen_dps(records: GyroRecords, thermal: ThermalModel, rows: np.ndarray,
                    site: dict[str, Any]) -> np.ndarray:
    """(3,) how far the bias wanders about the calibration, per axis, as its calibration records at rest and at
    slow rates show it: their excess scatter about the thermal model beyond noise and quantisation. A flicker-like wander departs from
    its mean over hours by more than the Allan floor (a minimum over the noise record's few minutes) says; the
    records, spread over the campaign, see the departure a check or a use will."""
    slow = rows[np.abs(records.reference_dps[rows]).max(axis=1) <= SLOW_RATE_DPS]
    if len(slow) <= gyro_model.N_PARAMETERS:
        return np.zeros(3)
    return joint_misfit_dps(records, thermal, slow, np.zeros(3), site)


def joint_misfit_dps(records: GyroRecords, thermal: ThermalModel, rows: np.ndarray,
                     wander_dps: np.ndarray, site: dict[str, Any]) -> np.ndarray:
    """(3,) a joint thermal fit's lack of fit, per axis: what its calibration records scatter about it beyond
    their noise, quantisation, the table's pointing across each turning axis (a source of its own) and the bias's wander
    (`wander_dps`, one too), where that scatter is evidently more (χ² beyond its 99 % quantile); zero else. The
    ramp method's per-band estimates are no measure of it: a band's fit takes its records, which a lagging
    fixture spreads over several degrees, at one temperature, and scatters by that."""
    predicted = gyro_model.distort_rate(records.reference_dps[rows], records.force_g[rows],
                                        thermal.parameters_at(records.temperature_c[rows], "extrapolate"))
    residual = predicted - records.mean_dps[rows]
    reference = records.reference_dps[rows]
    pointing2 = (np.sum(reference**2, axis=1, keepdims=True) - reference**2) * _systematic_sigma(site)["cross"] ** 2
    noise2 = (np.maximum(records.stderr_dps[rows], STDERR_FLOOR_DPS) ** 2 + quantisation_sigma(records)[rows] ** 2
              + pointing2 + np.asarray(wander_dps, dtype=float) ** 2)
    dof = max(len(rows) - gyro_model.N_PARAMETERS * (thermal.degree + 1) // 3, 1)
    evident = np.sum(residual**2 / noise2, axis=0) > chi2.ppf(0.99, dof)
    excess = np.maximum(np.sum(residual**2, axis=0) / dof - np.mean(noise2, axis=0), 0.0)
    return np.where(evident, np.sqrt(excess), 0.0)


def _systematic_sigma(site: dict[str, Any]) -> dict[str, float]:
    """The systematic errors as 1σ of what they shift: the table's rate accuracy (± uniform, a common relative
    error of every rate) the scale factors; its position accuracy (± uniform per axis: the fixture axis a rate
    step turns about is tilted by it, the same for every rate of the step's pose) the cross-axis terms; the
    Earth's rate the rig config does not place (± uniform, its size) the bias."""
    if site["latitude_deg"] is None:
        earth = EARTH_RATE_DPS
    elif site["heading_deg"] is None:
        earth = EARTH_RATE_DPS * float(np.cos(np.radians(site["latitude_deg"])))
    else:
        earth = 0.0
    return {"scale": site["rate_accuracy_pct"] / 100.0 / np.sqrt(3.0),
            "cross": float(np.radians(site["accuracy_arcsec"] / 3600.0)) / np.sqrt(3.0),
            "earth_dps": earth / np.sqrt(3.0)}


def _temperature_scatter_c(records: GyroRecords, groups: list[np.ndarray]) -> float:
    """A record's temperature reading's scatter about its setpoint's line in time: the uncertainty of the
    temperature a compensation is evaluated at."""
    residuals, fitted = [], 0
    for group in groups:
        t, temperature = records.t_s[group], records.temperature_c[group]
        if len(group) >= 3 and np.ptp(t) > 0:
            line = np.polynomial.Polynomial.fit(t, temperature, 1)
            residuals.append(temperature - line(t))
            fitted += 2
        else:
            residuals.append(temperature - temperature.mean())
            fitted += 1
    pooled = np.concatenate(residuals)
    return float(np.sqrt(np.sum(pooled**2) / max(len(pooled) - fitted, 1)))


def _bias_wander_dps(allan: dict[str, Any] | None) -> np.ndarray:
    """How far a bias wanders between when it is measured and when it is used, 1σ per axis: the flicker floor
    of the Allan deviation, 0.664 × the bias instability the noise record measured (its upper bound where the
    record could not resolve it); zero without a noise record (then said so)."""
    if allan is None or "bias_instability_dph" not in allan:
        return np.zeros(3)
    return np.array([FLICKER_FLOOR * (a["value"] or a["high"]) / 3600.0 for a in allan["bias_instability_dph"]])


def _with_systematics(fit: GyroSetpointFit, systematic: dict[str, Any]) -> np.ndarray:
    """A setpoint fit's 1σ with the systematic errors combined in."""
    sigma = fit.sigma.copy()
    sigma[gyro_model.BIAS] = np.hypot(sigma[gyro_model.BIAS], systematic["bias_instability_dps"])
    sigma[gyro_model.SCALE] = np.hypot(sigma[gyro_model.SCALE], fit.parameters[gyro_model.SCALE] * systematic["scale"])
    sigma[gyro_model.CROSS] = np.hypot(sigma[gyro_model.CROSS], systematic["cross"])
    return sigma


def _truth_error(records: GyroRecords, setpoints: np.ndarray, groups: list[np.ndarray], fits: list[GyroSetpointFit],
                 systematic: dict[str, Any]) -> list[dict[str, Any]]:
    """Estimate minus truth for every parameter at every setpoint, with its 1σ (the table's systematic errors
    combined in) and z."""
    assert records.truth_parameters is not None
    out = []
    for setpoint, group, fit in zip(setpoints, groups, fits):
        true = records.truth_parameters[group].mean(axis=0)
        sigma = _with_systematics(fit, systematic)
        for k, name in enumerate(gyro_model.PARAMETER_NAMES):
            error = float(fit.parameters[k] - true[k])
            out.append({"parameter": name, "setpoint_c": float(setpoint), "error": error, "sigma": float(sigma[k]),
                        "z": error / float(sigma[k])})
    return out
