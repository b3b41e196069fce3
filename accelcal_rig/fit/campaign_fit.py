"""Fit every DUT of a campaign: LM per setpoint, polynomials over temperature, metrics, truth scoring."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.fit.calibration import FORMAT_NAME as CALIBRATION_FORMAT
from accelcal_rig.fit.calibration import FORMAT_VERSION as CALIBRATION_VERSION
from accelcal_rig.fit.calibration import (
    CalibrationFile,
    PolynomialModel,
    SensorCalibration,
    SetpointFit,
    plain,
    save_calibration,
)
from accelcal_rig.fit.joint import fit_joint
from accelcal_rig.fit.lm import FitMode, FreeParameters, SfemFit, fit_sfem
from accelcal_rig.fit.metrics import drift_mg, noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.sfem import PARAMETER_NAMES, correct, norm_only_gauge
from accelcal_rig.fit.thermal import OutOfRange, ThermalModel, fit_thermal
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


def fit_dut(poses: DutPoses, options: FitOptions) -> DutFitResult:
    setpoints = np.array(list(dict.fromkeys(poses.setpoint_c.tolist())))
    groups = [np.flatnonzero(poses.setpoint_c == s) for s in setpoints]
    pose_temperatures = smoothed_temperatures(poses, groups)
    temperatures = np.array([pose_temperatures[g].mean() for g in groups])
    fits = []
    for setpoint, group in zip(setpoints, groups):
        try:
            fits.append(fit_sfem(poses.mean_g[group], poses.stderr_g[group],
                                 poses.reference_g[group] if options.mode == "reference" else None,
                                 options.mode, options.free, np.radians(poses.reference_accuracy_arcsec / 3600)))
        except ValueError as exc:
            raise type(exc)(f"sensor {poses.serial} at {setpoint:g} °C: {exc}") from None
    estimates = np.array([f.parameters for f in fits])
    sigmas = np.array([f.sigma for f in fits])
    free = fits[0].free
    thermal = fit_thermal(temperatures, estimates, sigmas, free, options.degree)
    if options.temperature_model == "joint":
        thermal = fit_joint(thermal, free, pose_temperatures, poses.mean_g, poses.stderr_g,
                            poses.reference_g if options.mode == "reference" else None, options.mode,
                            np.radians(poses.reference_accuracy_arcsec / 3600))
    compensated = correct(poses.mean_g, thermal.parameters_at(pose_temperatures, "extrapolate"))
    metrics = _metrics(poses, setpoints, groups, temperatures, fits, thermal, compensated, options)
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
        metrics={k: v for k, v in plain(metrics).items() if k != "truth_error"},
        warnings=thermal.warnings,
    )
    return DutFitResult(poses.serial, setpoints, temperatures, fits, thermal, compensated, metrics, calibration)


def _metrics(poses: DutPoses, setpoints: np.ndarray, groups: list[np.ndarray], temperatures: np.ndarray,
             fits: list[SfemFit], thermal: ThermalModel, compensated: np.ndarray,
             options: FitOptions) -> dict[str, Any]:
    by_setpoint = []
    for setpoint, temperature, group, fit in zip(setpoints, temperatures, groups, fits):
        by_setpoint.append({
            "setpoint_c": setpoint, "temperature_c": temperature,
            "before_mg": norm_rmse_mg(poses.mean_g[group]),
            "polynomial_mg": norm_rmse_mg(compensated[group]),
            "measurement_mg": norm_rmse_mg(correct(poses.mean_g[group], fit.parameters)),
        })
    # Zero-g offset at each temperature: before, the fitted raw bias; after, what the polynomial model
    # makes of that same raw zero-g reading.
    bias = np.array([f.parameters[0:3] for f in fits])
    offset_after = correct(bias, thermal.parameters_at(temperatures, "extrapolate"))
    metrics: dict[str, Any] = {
        "rmse_before_mg": norm_rmse_mg(poses.mean_g),
        "rmse_after_mg": norm_rmse_mg(compensated),
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
                 source: dict[str, str]) -> tuple[CalibrationFile, dict[str, Any]]:
    """Fit every DUT of a stored campaign; the calibration file and the report `rig fit --json` prints
    (per serial). Nothing is written: the campaign's measurements are only read."""
    results = [fit_dut(read_dut_poses(campaign, serial), options) for serial in campaign.serials]
    calibration = CalibrationFile(
        format=CALIBRATION_FORMAT, format_version=CALIBRATION_VERSION, created=utc_now(),
        software_version=__version__, source=source, sensors={r.serial: r.calibration for r in results},
    )
    report = {r.serial: {**plain(r.metrics), "warnings": r.thermal.warnings} for r in results}
    return calibration, report


def fit_and_save(campaign: Campaign, campaign_path: Path, calibration_path: Path,
                 options: FitOptions) -> tuple[CalibrationFile, dict[str, Any]]:
    """`fit_campaign`, then the calibration file written to `calibration_path` (replaced whole)."""
    if not campaign.poses:
        raise ValueError(f"{campaign_path}: no poses stored, nothing to fit")
    source = {"campaign": str(campaign_path), "measurements_sha256": measurements_sha256(campaign),
              "procedure": str(campaign.attrs.get("procedure_name", ""))}
    calibration, report = fit_campaign(campaign, options, source)
    save_calibration(calibration, calibration_path)
    return calibration, report


def summary_line(report: dict[str, Any], calibration_path: Path) -> str:
    """`calibration → cal.yaml: |g| RMSE 14.3 → 0.013 mg (floor 0.012) for 4 DUTs` style."""
    before = max(r["rmse_before_mg"] for r in report.values())
    after = max(r["rmse_after_mg"] for r in report.values())
    floor = max(r["noise_floor_mg"] for r in report.values())
    drift = max(max(r["drift_after_mg"]) for r in report.values())
    return (f"calibration → {calibration_path}: |g| RMSE {before:.2f} → {after:.4f} mg (noise floor {floor:.4f} mg), "
            f"offset drift after ≤ {drift:.4f} mg, {len(report)} DUTs (worst of each)")
