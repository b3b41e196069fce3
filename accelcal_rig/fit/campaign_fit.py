"""Fit every DUT of a campaign: LM per setpoint, polynomials over temperature, metrics, truth scoring."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial as bind
from pathlib import Path
from typing import Any, Literal

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.fit.acceptance import NOT_JUDGED, Judgement, combined_verdict, judge, recorded_acceptance
from accelcal_rig.fit.approach import approach_directions, temperature_rates_c_per_min
from accelcal_rig.fit.budget import (
    FittedTerms,
    budget,
    calibration_covariance,
    fitted_powers,
    smoothed_temperature_u_c,
    temperature_scatter_c,
    truth_coverage,
)
from accelcal_rig.fit.calibration import (
    ACCELERATION,
    ANGULAR_RATE,
    CalibrationFile,
    DutCalibration,
    GyroCalibration,
    PolynomialModel,
    SensorCalibration,
    SetpointFit,
    plain,
    save_calibration,
)
from accelcal_rig.fit.calibration import FORMAT_NAME as CALIBRATION_FORMAT
from accelcal_rig.fit.calibration import FORMAT_VERSION as CALIBRATION_VERSION
from accelcal_rig.fit.early_check import dropped
from accelcal_rig.fit.expected import expected_norm_rmse_mg, expected_reference_rmse_mg, thermal_jacobian
from accelcal_rig.fit.fixture_pool import map_over_duts
from accelcal_rig.fit.gyro_acceptance import judge_gyro
from accelcal_rig.fit.gyro_fit import GyroDesignError, GyroFitResult, fit_gyro, read_gyro_records, site_of
from accelcal_rig.fit.joint import fit_joint
from accelcal_rig.fit.lm import FitMode, FreeParameters, SfemFit, fit_sfem, norm_sigma
from accelcal_rig.fit.metrics import drift_mg, noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.noise_record import noise_allan
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty, certificate_temperatures, of_sensor
from accelcal_rig.fit.sfem import PARAMETER_NAMES, correct, norm_only_gauge
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel, fit_thermal
from accelcal_rig.fit.uncertainty import CoefficientCovariance
from accelcal_rig.fit.verification import ReferenceUncertainty, pose_figures
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.read import DutPoses, read_dut_poses
from accelcal_rig.store.records import utc_now

TemperatureModel = Literal["per-setpoint", "joint"]


@dataclass(frozen=True)
class FitOptions:
    mode: FitMode = "reference"
    degree: int = 3
    free: FreeParameters = "all"
    out_of_range: OutOfRange = "clamp"
    temperature_model: TemperatureModel = "per-setpoint"
    #: "on": the joint fit's bias carries ±h by each pose's direction of approach (a bidirectional ramp).
    hysteresis: str = "off"


@dataclass(frozen=True)
class DutFitResult:
    serial: str
    setpoints_c: np.ndarray           # (K,)
    temperatures_c: np.ndarray        # (K,) mean DUT temperature at each setpoint
    fits: list[SfemFit]
    thermal: ThermalModel
    compensated_g: np.ndarray         # (N, 3) every pose compensated with the polynomial model
    metrics: dict[str, Any]
    calibration: SensorCalibration
    parameter_u: ParameterUncertainty  # each parameter's own uncertainty at a temperature (limits judge with it)


def smoothed_temperatures(poses: DutPoses, groups: list[np.ndarray]) -> np.ndarray:
    """Each pose's DUT temperature from a straight line in time through its setpoint's readings.

    The ADXL355 reads temperature in 0.11 °C steps, so one pose's reading is ~0.04 °C off — at 0.2 mg/°C
    of bias drift, as much error as the noise floor. During a setpoint's poses the sensor's temperature
    moves smoothly (a few hundredths of a degree), which a line in time follows and the steps do not.
    """
    smoothed = poses.temperature_c.astype(float).copy()
    for group in groups:
        if len(group) >= 3 and np.ptp(poses.t_s[group]) > 0:
            line = np.polynomial.Polynomial.fit(poses.t_s[group], poses.temperature_c[group], 1)
            smoothed[group] = line(poses.t_s[group])
    return smoothed


def fit_dut(stored: DutPoses, options: FitOptions) -> DutFitResult:
    """Fit the calibration poses; judge the result on them (in-sample) and on the verification poses."""
    poses = stored.subset(~stored.verification)
    if not len(poses.setpoint_c):
        raise ValueError(f"sensor {stored.serial}: no calibration poses stored, nothing to fit")
    setpoints = np.array(list(dict.fromkeys(poses.setpoint_c.tolist())))
    groups = [np.flatnonzero(poses.setpoint_c == s) for s in setpoints]
    pose_temperatures = smoothed_temperatures(poses, groups)
    temperatures = np.array([pose_temperatures[g].mean() for g in groups])
    fits = []
    for setpoint, group in zip(setpoints, groups):
        try:
            fits.append(fit_sfem(poses.mean_g[group], poses.stderr_g[group],
                                 poses.reference_g[group] if options.mode == "reference" else None,
                                 options.mode, options.free, np.radians(poses.reference_accuracy_arcsec / 3600),
                                 poses.gravity_g))
        except ValueError as exc:
            raise type(exc)(f"sensor {poses.serial} at {setpoint:g} °C: {exc}") from None
    estimates = np.array([f.parameters for f in fits])
    sigmas = np.array([f.sigma for f in fits])
    free = fits[0].free
    thermal = fit_thermal(temperatures, estimates, sigmas, free, options.degree)
    approach = _both_ways(poses) if options.hysteresis == "on" and options.temperature_model == "joint" else None
    rate = poses.rate_c_per_min if approach is not None else None
    hysteresis_g, rate_g = np.zeros(3), np.zeros(3)
    if options.temperature_model == "joint":
        thermal, hysteresis_g, rate_g = fit_joint(thermal, free, pose_temperatures, poses.mean_g, poses.stderr_g,
                                                  poses.reference_g if options.mode == "reference" else None,
                                                  options.mode, np.radians(poses.reference_accuracy_arcsec / 3600),
                                                  poses.gravity_g, approach, rate)
    # In-sample: the fit as fitted (its hysteresis and rate terms removed); the calibration delivered, and
    # so the verification, knows neither: it is the sensor at rest, the mean of both directions.
    unhysteretic_g = poses.mean_g
    if approach is not None and rate is not None:
        unhysteretic_g = poses.mean_g - approach[:, None] * hysteresis_g - rate[:, None] * rate_g
    compensated = correct(unhysteretic_g, thermal.parameters_at(pose_temperatures, "extrapolate"))
    metrics = _metrics(poses, setpoints, groups, temperatures, fits, thermal, compensated, options)
    metrics["expected_fit_rmse_mg"] = _expected_rmse_mg(poses, groups, fits, thermal, pose_temperatures, options)
    if approach is not None:  # warming minus cooling, per axis: what the calibration (their mean) leaves ± half of
        metrics["hysteresis_mg"] = (2e3 * hysteresis_g).tolist()
        metrics["rate_bias_mg_per_c_per_min"] = (1e3 * rate_g).tolist()
    elif options.hysteresis == "on":
        thermal.warnings.append("fit.hysteresis not fitted: " + (
            "the temperature model is not joint" if options.temperature_model != "joint" else
            f"fewer than {MIN_POSES_EACH_WAY} poses approached warming and cooling over a common range of "
            "temperature (a campaign stopped before its way back?)"))
    for row, group, fit in zip(metrics["rmse_by_setpoint"], groups, fits):
        row["expected_mg"] = _expected_rmse_mg(poses, [group], [fit], None, pose_temperatures, options)
    align = options.mode == "norm-only"
    metrics["in_sample"] = pose_figures(compensated, poses.reference_g, poses.stderr_g, poses.setpoint_c,
                                        pose_temperatures, align, poses.gravity_g)
    joint = options.temperature_model == "joint"
    terms = FittedTerms(approach, hysteresis_g, rate, rate_g) if approach is not None and rate is not None else None
    covariance = calibration_covariance(poses, groups, fits, thermal, temperatures, pose_temperatures, options.mode,
                                        joint, terms)
    scatter_c = temperature_scatter_c(poses, pose_temperatures, len(groups))
    metrics["uncertainty_budget"] = budget(poses, covariance, thermal, temperatures, scatter_c)
    metrics["expanded_uncertainty_mg"] = metrics["uncertainty_budget"]["expanded_mg"]
    parameter_u = of_sensor(thermal, covariance, poses.gravity_uncertainty_g / poses.gravity_g)
    metrics["parameter_uncertainty"] = parameter_u.expanded_table(certificate_temperatures(thermal.domain_c),
                                                                  list(PARAMETER_NAMES))
    if stored.verification.any():
        checks = stored.subset(stored.verification)
        metrics["verification"], coverage = _verification(checks, thermal, options, covariance, scatter_c)
        if coverage is not None:
            metrics["truth_coverage_k2"] = coverage
    calibration = SensorCalibration(
        serial=poses.serial, mode=options.mode,
        free_parameters=[n for n, f in zip(PARAMETER_NAMES, free) if f],
        range_g=poses.range_g, lsb_g=poses.lsb_g,
        validity_c=thermal.domain_c, out_of_range=options.out_of_range,
        polynomial=PolynomialModel(domain_c=thermal.domain_c, degree=options.degree,
                                   coefficients={n: plain(c) for n, c in zip(PARAMETER_NAMES, thermal.coefficients)}),
        setpoints=[
            SetpointFit(setpoint_c=float(s), temperature_c=float(t), n_poses=f.n_poses,
                        chi2_reduced=plain(f.chi2_reduced),
                        parameters=dict(zip(PARAMETER_NAMES, plain(f.parameters))),
                        sigma=dict(zip(PARAMETER_NAMES, plain(f.sigma))))
            for s, t, f in zip(setpoints, temperatures, fits)
        ],
        metrics=_file_metrics(plain(metrics)),
        warnings=thermal.warnings,
    )
    return DutFitResult(poses.serial, setpoints, temperatures, fits, thermal, compensated, metrics, calibration,
                        parameter_u)


def _file_metrics(metrics: dict[str, Any]) -> dict[str, Any]:
    """What the calibration file keeps of the figures: all but the simulation truth's errors, and of the
    budget at each temperature the totals (each source's share there is in `rig fit --json`)."""
    kept = {k: v for k, v in metrics.items() if k != "truth_error"}
    budget = dict(kept["uncertainty_budget"])
    budget["by_temperature"] = [{k: v for k, v in row.items() if k != "sources_mg"} for row in budget["by_temperature"]]
    return {**kept, "uncertainty_budget": budget}


def _expected_rmse_mg(poses: DutPoses, groups: list[np.ndarray], fits: list[SfemFit], thermal: ThermalModel | None,
                      pose_temperatures: np.ndarray, options: FitOptions) -> float:
    """The in-sample |g| RMSE the fit is expected to reach: of the thermal model's coefficients over every
    pose, or (`thermal` None) of one setpoint's parameters."""
    rows = np.concatenate(groups)
    if thermal is None:
        jacobian = fits[0].jacobian
    else:
        n_powers = fitted_powers(thermal, len(groups), options.temperature_model == "joint")
        powers = [np.vander(thermal.scaled(pose_temperatures[g]), n_powers, increasing=True) for g in groups]
        jacobian = thermal_jacobian([f.jacobian for f in fits], powers, 3 if options.mode == "reference" else 1)
    if options.mode == "reference":
        return expected_reference_rmse_mg(jacobian, poses.reference_g[rows], poses.stderr_g[rows],
                                          np.radians(poses.reference_accuracy_arcsec / 3600))
    return expected_norm_rmse_mg(jacobian, norm_sigma(poses.mean_g[rows], poses.stderr_g[rows]))


def _verification(checks: DutPoses, thermal: ThermalModel, options: FitOptions, covariance: CoefficientCovariance,
                  scatter_c: float) -> tuple[dict[str, Any], float | None]:
    """The figures on poses the fit never saw, compensated as `apply` would (the calibration's out-of-range
    rule), each at its own smoothed temperature; and in a dry run the share of their axis errors against
    the truth inside the expanded uncertainty."""
    groups = [np.flatnonzero(checks.setpoint_c == s) for s in dict.fromkeys(checks.setpoint_c.tolist())]
    temperatures = smoothed_temperatures(checks, groups)
    compensated = correct(checks.mean_g, thermal.parameters_at(temperatures, options.out_of_range))
    references = ReferenceUncertainty(np.radians(checks.reference_accuracy_arcsec / 3600),
                                      checks.gravity_uncertainty_g / checks.gravity_g)
    figures = pose_figures(compensated, checks.reference_g, checks.stderr_g, checks.setpoint_c, temperatures,
                           options.mode == "norm-only", checks.gravity_g, references)
    coverage = truth_coverage(checks, covariance, thermal, compensated, temperatures,
                              smoothed_temperature_u_c(checks.t_s, groups, scatter_c), options.mode, options.out_of_range)
    return figures, coverage


def _metrics(poses: DutPoses, setpoints: np.ndarray, groups: list[np.ndarray], temperatures: np.ndarray,
             fits: list[SfemFit], thermal: ThermalModel, compensated: np.ndarray,
             options: FitOptions) -> dict[str, Any]:
    by_setpoint = []
    for setpoint, temperature, group, fit in zip(setpoints, temperatures, groups, fits):
        by_setpoint.append({
            "setpoint_c": setpoint, "temperature_c": temperature,
            "before_mg": norm_rmse_mg(poses.mean_g[group], poses.gravity_g),
            "polynomial_mg": norm_rmse_mg(compensated[group], poses.gravity_g),
            "measurement_mg": norm_rmse_mg(correct(poses.mean_g[group], fit.parameters), poses.gravity_g),
        })
    # Zero-g offset at each temperature: before, the fitted raw bias; after, what the polynomial model
    # makes of that same raw zero-g reading.
    bias = np.array([f.parameters[0:3] for f in fits])
    offset_after = correct(bias, thermal.parameters_at(temperatures, "extrapolate"))
    metrics: dict[str, Any] = {
        "rmse_before_mg": norm_rmse_mg(poses.mean_g, poses.gravity_g),
        "rmse_after_mg": norm_rmse_mg(compensated, poses.gravity_g),
        "gravity_m_s2": poses.gravity_g * STANDARD_GRAVITY_M_S2,
        "rmse_by_setpoint": by_setpoint,
        "drift_before_mg": drift_mg(bias),
        "drift_after_mg": drift_mg(offset_after),
        "noise_floor_mg": noise_floor_mg(poses.mean_g, poses.stderr_g),
        "chi2_reduced": [f.chi2_reduced for f in fits],
        "temperature_range_c": [float(temperatures.min()), float(temperatures.max())],
    }
    if poses.truth_parameters is not None:
        metrics["truth_error"] = _truth_error(poses.truth_parameters, setpoints, groups, fits, options.mode)
    return metrics


def _truth_error(truth: np.ndarray, setpoints: np.ndarray, groups: list[np.ndarray], fits: list[SfemFit],
                 mode: FitMode) -> list[dict[str, Any]]:
    """Estimate minus truth for every fitted parameter, in the fit's own gauge, with its 1σ and z."""
    records = []
    for setpoint, group, fit in zip(setpoints, groups, fits):
        true = truth[group].mean(axis=0)
        if mode == "norm-only":
            true = norm_only_gauge(true)
        for k in np.flatnonzero(fit.free):
            error = fit.parameters[k] - true[k]
            records.append({"parameter": PARAMETER_NAMES[k], "setpoint_c": float(setpoint), "error": float(error),
                            "sigma": float(fit.sigma[k]), "z": float(error / fit.sigma[k])})
    return records


def fit_campaign(campaign: Campaign, options: FitOptions,
                 source: dict[str, str], run_end: bool = False) -> tuple[CalibrationFile, dict[str, Any]]:
    """Fit every DUT of a stored campaign; the calibration file and the report `rig fit --json` prints
    (per serial). Nothing is written: the campaign's measurements are only read. `run_end`: the fit stage of
    the run itself, whose campaign is done but for the fit."""
    left_out = dropped(campaign.events)
    serials = [s for s in campaign.serials if s not in left_out]
    if not serials:
        raise ValueError(f"every DUT was dropped by the early check ({'; '.join(left_out.values())}): nothing to fit")
    stored = [read_dut_poses(campaign, s) for s in serials]  # each DUT's acceleration channel
    if options.hysteresis == "on":
        stored = [with_approach(campaign, poses) for poses in stored]
    results = map_over_duts(bind(fit_dut, options=options), stored)
    limits = recorded_acceptance(campaign.header.procedure_yaml, source.get("campaign", "the campaign"))
    partial = partial_campaign(campaign, run_end)
    judged = {r.serial: judge(r.metrics, r.thermal, options.mode, limits, partial, r.parameter_u) for r in results}
    noise = {serial: {channel: figures for channel in (ACCELERATION, ANGULAR_RATE)
                      if (figures := _noise_figures(campaign, serial, channel)) is not None}
             for serial in serials}
    gyroscopes = {serial: fit_gyroscope(campaign, serial, options, noise[serial].get(ANGULAR_RATE))
                  for serial in serials}
    gyro_verdicts = {serial: judge_gyro(gyro.metrics, gyro.thermal, limits, partial, gyro.parameter_u)
                     for serial, gyro in gyroscopes.items() if isinstance(gyro, GyroFitResult)}
    uncalibrated = {serial: not_calibrated(campaign, serial, gyroscopes[serial]) for serial in serials}
    duts = {}
    for r in results:
        accel = r.calibration.model_copy(update={
            "verdict": judged[r.serial].verdict, "verdict_reasons": judged[r.serial].reasons,
            "decision": judged[r.serial].plain(),
            "metrics": {**r.calibration.metrics, **_allan(noise[r.serial], ACCELERATION)}})
        channels: dict[str, SensorCalibration | GyroCalibration] = {ACCELERATION: accel}
        gyro = gyroscopes[r.serial]
        if isinstance(gyro, GyroFitResult):
            verdict = gyro_verdicts[r.serial]
            channels[ANGULAR_RATE] = gyro.calibration.model_copy(update={
                "verdict": verdict.verdict, "verdict_reasons": verdict.reasons, "decision": verdict.plain(),
                "metrics": {**gyro.calibration.metrics, **_allan(noise[r.serial], ANGULAR_RATE)}})
        duts[r.serial] = DutCalibration(channels=channels, not_calibrated=uncalibrated[r.serial])
    calibration = CalibrationFile(
        format=CALIBRATION_FORMAT, format_version=CALIBRATION_VERSION, created=utc_now(),
        software_version=__version__, source={**source, **({"partial": partial} if partial else {})}, duts=duts,
        dropped=left_out,
    )
    overall = {serial: dut_verdict(judged[serial], gyro_verdicts.get(serial)) for serial in judged}
    report = {r.serial: {**plain(r.metrics), "warnings": r.thermal.warnings, "verdict": overall[r.serial].verdict,
                         "verdict_reasons": overall[r.serial].reasons, "decision": judged[r.serial].plain(),
                         **_allan(noise[r.serial], ACCELERATION),
                         **({"gyro": {**gyro.metrics, "verdict": gyro_verdicts[r.serial].verdict,
                                      "verdict_reasons": gyro_verdicts[r.serial].reasons,
                                      "decision": gyro_verdicts[r.serial].plain(),
                                      **_allan(noise[r.serial], ANGULAR_RATE)}}
                            if isinstance(gyro := gyroscopes[r.serial], GyroFitResult) else {}),
                         **({"not_calibrated": uncalibrated[r.serial]} if uncalibrated[r.serial] else {})}
              for r in results}
    return calibration, report


def dut_verdict(accelerometer: Judgement, gyroscope: Judgement | None) -> Judgement:
    """A DUT's verdict from its sensors' (combined_verdict); the gyroscope's reasons follow the accelerometer's,
    each marked."""
    if gyroscope is None:
        return accelerometer
    verdicts = (accelerometer.verdict, gyroscope.verdict)
    failed = "FAIL" in verdicts
    pick = (lambda j: [r for r in j.reasons] if j.verdict == "FAIL" else []) if failed else (lambda j: list(j.reasons))
    return Judgement(combined_verdict(list(verdicts)), pick(accelerometer) + [f"gyro: {r}" for r in pick(gyroscope)])


def _noise_figures(campaign: Campaign, serial: str, channel: str) -> dict[str, Any] | None:
    """The channel's Allan figures where the campaign has noise records and the DUT the channel, else None."""
    odr_hz = float(campaign.header.duts[campaign.serials.index(serial)].get("odr_hz") or 0.0)
    if odr_hz <= 0 or channel not in {c.name for c in campaign.header.dut_channels(serial)}:
        return None
    return noise_allan(campaign, serial, channel, odr_hz)


def _allan(noise: dict[str, dict[str, Any]], channel: str) -> dict[str, Any]:
    """`{"allan": figures}` of a channel that has them, else {}."""
    return {"allan": plain(noise[channel])} if channel in noise else {}


#: The quantities a channel model calibrates: Eq. 1 against gravity; the rate-table model against the table's
#: rate and the Earth's.
CHANNEL_MODELS = {"acceleration": "Eq. 1 sensor-frame error model against gravity",
                  "angular rate": "rate-table gyroscope model (fit/gyro_model.py) against the table's rate"}


def fit_gyroscope(campaign: Campaign, serial: str, options: FitOptions,
                  allan: dict[str, Any] | None = None) -> GyroFitResult | str | None:
    """The DUT's gyroscope fitted from the campaign's rate steps; why not (a line) where it has a gyroscope
    but the campaign no rate steps or too few; None for a DUT without one."""
    reason = _no_rate_steps(campaign, serial)
    if reason is not None or ANGULAR_RATE not in {c.name for c in campaign.header.dut_channels(serial)}:
        return reason
    try:
        return fit_gyro(read_gyro_records(campaign, serial), options.degree, options.out_of_range, site_of(campaign),
                        allan)
    except GyroDesignError as exc:
        return f"angular rate in dps: measured and stored; not calibrated: {exc}"


def _no_rate_steps(campaign: Campaign, serial: str) -> str | None:
    """Why the DUT's gyroscope cannot be calibrated from this campaign: it stores no rate step (None: it
    does, or the DUT has no gyroscope)."""
    if ANGULAR_RATE not in {c.name for c in campaign.header.dut_channels(serial)}:
        return None
    if campaign.header.plan.keys_of("rate") & campaign.stored_keys:
        return None
    return ("angular rate in dps: measured and stored; the campaign has no rate steps to calibrate it (a rate "
            "table and a procedure with rates:)")


def not_calibrated(campaign: Campaign, serial: str, gyro: GyroFitResult | str | None = None) -> dict[str, str]:
    """The DUT's channels that no channel model calibrated, each with why (they are measured and stored): the
    gyroscope's from its fit (`gyro`, a reason where it failed), else from whether the campaign has rate steps."""
    reasons = {channel.name: f"{channel.quantity} in {channel.unit}: measured and stored; no channel model "
                             f"calibrates {channel.quantity} yet"
               for channel in campaign.header.dut_channels(serial) if channel.quantity not in CHANNEL_MODELS}
    reason = gyro if isinstance(gyro, str) else _no_rate_steps(campaign, serial) if gyro is None else None
    if reason is not None:
        reasons[ANGULAR_RATE] = reason
    return reasons


#: Poses each direction of approach needs before the hysteresis term is fitted.
MIN_POSES_EACH_WAY = 6


def _both_ways(poses: DutPoses) -> np.ndarray | None:
    """The poses' directions of approach if both occur often enough over a common range of temperature
    (else ±h and the constant bias could not be told apart: no term, and no figure)."""
    if poses.approach is None:
        return None
    warming, cooling = poses.temperature_c[poses.approach > 0], poses.temperature_c[poses.approach < 0]
    if min(len(warming), len(cooling)) < MIN_POSES_EACH_WAY:
        return None
    if max(warming.min(), cooling.min()) >= min(warming.max(), cooling.max()):
        return None
    return poses.approach


def with_approach(campaign: Campaign, poses: DutPoses) -> DutPoses:
    """The DUT's poses with the direction each was approached from, read off its soaks and poses."""
    history_t, history_c = [], []
    for soak in campaign.soaks:
        serials = list(soak.serials) or campaign.serials
        if poses.serial in serials and len(soak.t_s):
            history_t.append(np.asarray(soak.t_s, dtype=float))
            history_c.append(np.asarray(soak.dut_c, dtype=float)[:, serials.index(poses.serial)])
    history = (poses.t_s, poses.temperature_c, np.concatenate(history_t or [np.zeros(0)]),
               np.concatenate(history_c or [np.zeros(0)]))
    return replace(poses, approach=approach_directions(*history), rate_c_per_min=temperature_rates_c_per_min(*history))


def partial_campaign(campaign: Campaign, run_end: bool = False) -> str:
    """How a campaign fell short of its plan, or "" when every planned pose is stored (and it was not
    aborted: a run's own fit stage sees its campaign still running)."""
    stored, planned = len(campaign.poses), campaign.poses_planned
    state = "done" if run_end else campaign.state  # a run's own fit stage: its campaign is done but for the fit
    if stored >= planned and state != "aborted":
        return ""
    skipped = any(e.kind == "soak" and "setpoint skipped" in e.message for e in campaign.events)
    why = "a soak timed out and its setpoint was skipped" if skipped and state == "done" else f"state {state}"
    return f"partial campaign: {stored} of {planned} poses stored ({why})"


def fit_and_save(campaign: Campaign, campaign_path: Path, calibration_path: Path,
                 options: FitOptions, run_end: bool = False) -> tuple[CalibrationFile, dict[str, Any]]:
    """`fit_campaign`, then the calibration file written to `calibration_path` (replaced whole)."""
    if not campaign.poses:
        raise ValueError(f"{campaign_path}: no poses stored, nothing to fit")
    source = {"campaign": str(campaign_path), "measurements_sha256": measurements_sha256(campaign),
              "procedure": str(campaign.attrs.get("procedure_name", ""))}
    calibration, report = fit_campaign(campaign, options, source, run_end)
    save_calibration(calibration, calibration_path)
    return calibration, report


def summary_line(report: dict[str, Any], calibration_path: Path) -> str:
    """`calibration → cal.yaml: verification |g| RMSE 0.013 mg (noise floor 0.012), …; 4 PASS` style: the
    held-out figures when there are verification poses, else the in-sample ones, said so."""
    before = max(r["rmse_before_mg"] for r in report.values())
    verified = all("verification" in r for r in report.values())
    floor = max((r["verification"] if verified else r)["noise_floor_mg"] for r in report.values())
    if verified:
        after = max(r["verification"]["rmse_mg"] for r in report.values())
        drift = max(max(r["verification"]["drift_mg"]) for r in report.values())
        figures = (f"|g| RMSE {before:.2f} → {after:.4f} mg on verification poses (noise floor {floor:.4f} mg), "
                   f"residual drift ≤ {drift:.4f} mg")
    else:
        after = max(r["rmse_after_mg"] for r in report.values())
        drift = max(max(r["drift_after_mg"]) for r in report.values())
        figures = (f"|g| RMSE {before:.2f} → {after:.4f} mg in-sample, no verification poses (noise floor "
                   f"{floor:.4f} mg), offset drift after ≤ {drift:.4f} mg")
    gyros = [r["gyro"] for r in report.values() if "gyro" in r]
    if gyros:
        checked = all("verification" in g and g["verification"]["rmse_dps"] is not None for g in gyros)
        key = "verification" if checked else None
        before = max((g[key] if key else g)["rmse_before_dps"] for g in gyros)
        after = max(g[key]["rmse_dps"] if key else g["rmse_after_dps"] for g in gyros)
        figures += (f"; gyro rate RMS {before:.3f} → {after:.4f} °/s "
                    f"{'at verification rates' if checked else 'in-sample, no verification rates'}, expanded "
                    f"uncertainty ≤ {max(max(g['expanded_uncertainty_dps']) for g in gyros):.4f} °/s at "
                    f"{gyros[0]['uncertainty_budget']['largest_rate_dps']:g} °/s")
    failed = [serial for serial, r in report.items() if r.get("verdict") == "FAIL"]
    unjudged = sum(r.get("verdict") == NOT_JUDGED for r in report.values())
    conditional = [serial for serial, r in report.items() if r.get("verdict") == "CONDITIONAL"]
    passed = len(report) - len(failed) - unjudged - len(conditional)
    verdicts = (f"{passed} PASS, {len(failed)} FAIL ({', '.join(failed)})" if failed else f"{passed} PASS")
    if conditional:  # inside a guard band: the procedure's decision rule states neither pass nor fail
        verdicts += f", {len(conditional)} CONDITIONAL ({', '.join(conditional)})"
    if unjudged:
        verdicts = (f"{unjudged} NOT JUDGED (no acceptance limits stated)" if unjudged == len(report)
                    else f"{verdicts}, {unjudged} NOT JUDGED")
    uncalibrated = sorted({channel for r in report.values() for channel in r.get("not_calibrated", {})})
    left = f"; not calibrated (measured and stored): {', '.join(uncalibrated)}" if uncalibrated else ""
    return f"calibration → {calibration_path}: {figures}, {len(report)} DUTs (worst of each); {verdicts}{left}"
