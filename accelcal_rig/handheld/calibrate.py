"""A norm-only calibration from the static intervals of a recording, written as the same calibration
file as `rig fit` (one temperature: every parameter a constant); and, when the recording has gyro columns,
the gyroscope's bias and g-sensitivity from those intervals and K from the moves between them (handheld.gyro),
as the file's gyro channel."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2, site_gravity_g
from accelcal_rig.fit import acceleration, angular_rate, gyro_model
from accelcal_rig.fit.calibration import (
    FORMAT_NAME,
    FORMAT_VERSION,
    CalibrationFile,
    ChannelCalibration,
    DutCalibration,
    PolynomialModel,
    SetpointFit,
    plain,
)
from accelcal_rig.fit.lm import DegenerateDesign, FreeParameters, SfemFit
from accelcal_rig.fit.metrics import noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.robust import fit_norm_only_with_floor
from accelcal_rig.fit.sfem import correct
from accelcal_rig.handheld.gyro import GSENS_ALPHA, HandheldGyroFit, fit_handheld_gyro
from accelcal_rig.handheld.recording import Recording, RecordingUnusable
from accelcal_rig.handheld.static_intervals import Detection
from accelcal_rig.store.records import utc_now

#: A half-axis counts as visited when some interval puts at least this much gravity along it.
VISITED_G = 0.5
#: Temperature assumed when a recording has none (and none is given).
NOMINAL_TEMPERATURE_C = 25.0
#: Beyond this χ²_red (the intervals against their own standard errors, before any scatter floor) a fit is
#: implausible: the intervals scatter ten times more than their noise explains, so they were not still or the
#: time base is wrong. Hand-held recordings held still reach a few (the real session of tests/data: 4 at most).
MAX_CHI2_REDUCED = 100.0


@dataclass(frozen=True)
class RecordingFit:
    fit: SfemFit
    calibration: CalibrationFile
    report: dict[str, Any]
    gyro: HandheldGyroFit | None = None  # when the recording has gyro columns


def missing_orientations(mean_g: np.ndarray) -> list[str]:
    """Half-axes no interval points along: `x down` when no interval has x ≤ −0.5 g, and so on."""
    direction = mean_g / np.linalg.norm(mean_g, axis=1, keepdims=True)
    missing = []
    for axis, name in enumerate("xyz"):
        if not np.any(direction[:, axis] >= VISITED_G):
            missing.append(f"{name} up")
        if not np.any(direction[:, axis] <= -VISITED_G):
            missing.append(f"{name} down")
    return missing


#: A recording's channels, named as the built-in parts name an IMU's (a recording's columns are an accelerometer's
#: and, where it has them, a gyroscope's).
ACCEL_CHANNEL, GYRO_CHANNEL = "accel", "gyro"
#: Eq. 1's parameters as the accelerometer's model names them.
PARAMETER_NAMES = acceleration.MODEL.parameter_names
#: What a hand-held recording can determine of the gyroscope: its bias, K (from the moves) and G (from the still
#: intervals, where they ask for it); the rest of the model holds its nominal value.
HANDHELD_BIAS = tuple(gyro_model.PARAMETER_NAMES[gyro_model.BIAS])
HANDHELD_K = tuple(gyro_model.PARAMETER_NAMES[gyro_model.SCALE.start:gyro_model.CROSS.stop])
HANDHELD_GSENS = tuple(gyro_model.PARAMETER_NAMES[gyro_model.GSENS])


def gyro_calibration(gyro: HandheldGyroFit, recording: Recording, serial: str, temperature_c: float,
                     validity_c: tuple[float, float]) -> ChannelCalibration:
    """The hand-held gyroscope fit as the calibration file's `gyro` channel: what the recording determined (the
    bias; K where the moves determined it; G where the still intervals asked for it) constant over its
    temperature, every other term of the rate-table model at its nominal value and said to be."""
    parameters = gyro_model.IDENTITY_PARAMETERS.copy()
    sigma = np.full(gyro_model.N_PARAMETERS, np.nan)
    parameters[gyro_model.BIAS], sigma[gyro_model.BIAS] = gyro.bias_dps, gyro.bias_sigma_dps
    free = list(HANDHELD_BIAS)
    if gyro.k_determined:
        parameters[gyro_model.SCALE], sigma[gyro_model.SCALE] = np.diag(gyro.matrix), np.diag(gyro.matrix_sigma)
        for column, (i, j) in enumerate(gyro_model.CROSS_TERMS):
            parameters[gyro_model.CROSS.start + column] = gyro.matrix[i, j]
            sigma[gyro_model.CROSS.start + column] = gyro.matrix_sigma[i, j]
        free += HANDHELD_K
    if gyro.gsens_fitted:
        parameters[gyro_model.GSENS], sigma[gyro_model.GSENS] = gyro.gsens_dps_per_g.ravel(), gyro.gsens_sigma.ravel()
        free += HANDHELD_GSENS
    names = gyro_model.PARAMETER_NAMES
    assert recording.gyro_dps is not None
    model = angular_rate.MODEL
    held = ["asymmetry", "nonlinearity"] + ([] if gyro.gsens_fitted else ["g-sensitivity"])
    k_said = ("the turns between still intervals define K relative to the gravity directions it measures"
              if gyro.k_determined else "K is not determined by this recording (its moves say nothing of it): the "
              "nominal sensitivity stands (scale 1, no cross-axis terms)")
    return ChannelCalibration(
        model=model.model_id, quantity=model.quantity, unit="dps", serial=serial, mode="hand-held",
        free_parameters=free,
        range=max(250.0, float(np.ceil(np.abs(recording.gyro_dps).max()))), lsb=recording.gyro_lsb_dps or 1.0,
        validity_c=validity_c, out_of_range="clamp",
        polynomial=PolynomialModel(domain_c=validity_c, degree=0,
                                   coefficients={n: [float(p)] for n, p in zip(names, parameters)}),
        setpoints=[SetpointFit(setpoint_c=temperature_c, temperature_c=temperature_c, n_poses=gyro.segments,
                               chi2_reduced=plain(gyro.chi2_reduced), parameters=dict(zip(names, plain(parameters))),
                               sigma=dict(zip(names, plain(sigma))))],
        statements={
            "earth_rate": "not taken out: a hand-held recording leaves the Earth's rate (up to 0.0042 °/s) in the bias",
            "gauge": f"the accelerometer's calibrated frame (its norm-only gauge): {k_said}; "
                     f"{', '.join(held)} not determined (held at zero)",
            "g_sensitivity": ("fitted to the still intervals' means against the compensated accelerometer"
                              if gyro.gsens_fitted else "not fitted") + (
                f" (F-test p = {gyro.gsens_p_value:.2g}, fitted below {GSENS_ALPHA:g})" if gyro.gsens_p_value is not None
                else " (the intervals' forces cannot separate it from the bias)")},
        metrics=plain({"residual_rms_before_deg": _rms_or_none(gyro.residual_before_deg),
                       "residual_rms_after_deg": _rms_or_none(gyro.residual_after_deg),
                       "segments": gyro.segments, "rank": gyro.rank, "condition": gyro.condition,
                       "k_determined": gyro.k_determined, "gsens_fitted": gyro.gsens_fitted}),
        warnings=list(gyro.notes))


def _rms_or_none(values: np.ndarray) -> float | None:
    return float(np.sqrt(np.mean(values ** 2))) if len(values) else None


def _refuse_implausible(recording: Recording, intervals: int, chi2_reduced: float | None) -> None:
    """A fit its own figures call implausible is refused (not written, not registered), in one line."""
    if chi2_reduced is None or not chi2_reduced > MAX_CHI2_REDUCED:  # NaN: no degrees of freedom left to judge by
        return
    raise RecordingUnusable(f"{recording.source}: implausible fit: its {intervals} static intervals scatter "
                            f"{np.sqrt(chi2_reduced):.0f} times more than their standard errors say (χ²_red "
                            f"{chi2_reduced:.0f}, above {MAX_CHI2_REDUCED:g}): they were not still, or the time base "
                            "is wrong (--time-unit, --rate-hz); no calibration written")


def fit_recording(recording: Recording, detection: Detection, free: FreeParameters, serial: str,
                  temperature_c: float | None = None, gravity_m_s2: float | None = None) -> RecordingFit:
    """A norm-only fit of the static intervals: |U_SF| fitted to the site's gravity (`gravity_m_s2`, else the
    standard value, with a warning), outputs in standard g."""
    gravity_g = site_gravity_g(STANDARD_GRAVITY_M_S2 if gravity_m_s2 is None else gravity_m_s2)
    intervals = detection.intervals
    needed = 6 if free == "bias-scale" else 9
    if len(intervals) < needed:
        raise RecordingUnusable(
            f"{recording.source}: {len(intervals)} static intervals found, a {needed}-parameter norm-only fit needs "
            f"at least {needed} (12 or more recommended)" + (
                ", or fit bias and scale only with --parameters bias-scale" if free == "all" and len(intervals) >= 6
                else ": hold the sensor still longer in each orientation, or lower --min-interval-s"))
    mean = np.array([i.mean_g for i in intervals])
    stderr = np.array([i.stderr_g for i in intervals])
    missing = missing_orientations(mean)
    if missing:
        raise RecordingUnusable(f"{recording.source}: {len(intervals)} static intervals, but none with "
                                f"{', '.join(missing)} (≥ {VISITED_G:g} g along it): record orientations with every "
                                "axis pointing up and down")
    try:
        robust = fit_norm_only_with_floor(mean, stderr, free, gravity_g)
    except DegenerateDesign as exc:
        raise RecordingUnusable(f"{recording.source}: {exc}") from None
    fit = robust.fit
    _refuse_implausible(recording, len(intervals), robust.chi2_reduced_before)
    if robust.scatter_floor_g > 0:
        recording_notes = [f"the intervals scatter more than their standard errors say (χ²_red "
                           f"{robust.chi2_reduced_before:.2f}): each weighed with a scatter floor of "
                           f"{robust.scatter_floor_g * 1e3:.4f} mg added (χ²_red {fit.chi2_reduced:.2f} after), so no "
                           "interval counts for more because it lasted longer"]
    else:
        recording_notes = []
    temperatures = np.array([i.temperature_c for i in intervals])
    warnings = list(recording.notes) + recording_notes
    if gravity_m_s2 is None:
        warnings.append(f"|g| fitted to the standard {STANDARD_GRAVITY_M_S2} m/s² (outputs in standard g); give the "
                        "site's gravity with --gravity-m-s2")
    if len(intervals) == int(fit.free.sum()):
        warnings.append(f"{len(intervals)} intervals for {len(intervals)} parameters: the fit passes through every "
                        "one, with no check left (record more orientations)")
    if np.all(np.isfinite(temperatures)):
        temperature = float(temperatures.mean())
        low, high = float(temperatures.min()), float(temperatures.max())
    else:
        temperature = NOMINAL_TEMPERATURE_C if temperature_c is None else temperature_c
        low = high = temperature
        if temperature_c is None:
            warnings.append(f"no temperature in the recording: {NOMINAL_TEMPERATURE_C:g} °C assumed "
                            "(give it with --temperature-c)")
    if high - low < 1.0:
        low, high = temperature - 0.5, temperature + 0.5  # one temperature: valid within ±0.5 °C of it
    compensated = correct(mean, fit.parameters)
    # The gyro after the accelerometer: its moves are judged against the compensated gravity directions.
    gyro = (fit_handheld_gyro(recording, intervals, compensated, detection.rate_hz,
                              correct(recording.accel_g, fit.parameters))
            if recording.gyro_dps is not None else None)
    metrics = {
        "rmse_before_mg": norm_rmse_mg(mean, gravity_g), "rmse_after_mg": norm_rmse_mg(compensated, gravity_g),
        "gravity_m_s2": gravity_g * STANDARD_GRAVITY_M_S2, "units": "standard g (9.80665 m/s²)",
        "noise_floor_mg": noise_floor_mg(mean, stderr), "chi2_reduced": fit.chi2_reduced,
        "chi2_reduced_before": robust.chi2_reduced_before, "scatter_floor_mg": robust.scatter_floor_g * 1e3,
        "n_intervals": len(intervals), "temperature_c": temperature,
    }
    calibration = ChannelCalibration(
        model=acceleration.MODEL.model_id, quantity=acceleration.MODEL.quantity, unit="g",
        serial=serial, mode="norm-only", free_parameters=[n for n, f in zip(PARAMETER_NAMES, fit.free) if f],
        range=max(2.0, float(np.ceil(np.abs(recording.accel_g).max()))), lsb=recording.lsb_g,
        validity_c=(low, high), out_of_range="clamp",
        polynomial=PolynomialModel(domain_c=(low, high), degree=0,
                                   coefficients={n: [float(p)] for n, p in zip(PARAMETER_NAMES, fit.parameters)}),
        setpoints=[SetpointFit(setpoint_c=temperature, temperature_c=temperature, n_poses=len(intervals),
                               chi2_reduced=plain(fit.chi2_reduced),
                               parameters=dict(zip(PARAMETER_NAMES, plain(fit.parameters))),
                               sigma=dict(zip(PARAMETER_NAMES, plain(fit.sigma))))],
        metrics=plain(metrics), warnings=warnings,
    )
    channels = {ACCEL_CHANNEL: calibration}
    if gyro is not None:
        channels[GYRO_CHANNEL] = gyro_calibration(gyro, recording, serial, temperature, (low, high))
    calibration_file = CalibrationFile(
        format=FORMAT_NAME, format_version=FORMAT_VERSION, created=utc_now(), software_version=__version__,
        source={"recording": recording.source, "measurements_sha256": recording.sha256,
                "procedure": "hand-held recording, norm-only"},
        duts={serial: DutCalibration(channels=channels)},
    )
    report = plain({
        "source": recording.source, "rate_hz": detection.rate_hz, "samples": len(recording.t_s),
        "threshold_g2": detection.threshold_g2, "init_variance_g2": detection.init_variance_g2,
        "intervals": [{"start_s": i.start_s, "end_s": i.end_s, "samples": i.n_samples, "mean_g": i.mean_g,
                       "norm_before_mg": float((np.linalg.norm(i.mean_g) - gravity_g) * 1e3),
                       "norm_after_mg": float((np.linalg.norm(c) - gravity_g) * 1e3), "temperature_c": i.temperature_c}
                      for i, c in zip(intervals, compensated)],
        "parameters": dict(zip(PARAMETER_NAMES, fit.parameters)),
        "sigma": dict(zip(PARAMETER_NAMES, fit.sigma)),
        **metrics, "warnings": warnings,
        "gyro": gyro.report() if gyro is not None else None,
    })
    return RecordingFit(fit, calibration_file, report, gyro)
