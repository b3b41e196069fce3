"""Everything a campaign report shows, read from the campaign file and fitted in memory.

The fit is redone here with the options the file records (the same result `rig fit` writes, the file is
only read), so a report works on a finished, an aborted or a still running campaign alike; when there
are too few poses to fit, the report shows what was measured and says why there is no fit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.config.procedure import SoakCriterion
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.errors import RigError
from accelcal_rig.fit.acceptance import Judgement, judge, recorded_acceptance
from accelcal_rig.fit.allan import AllanCurve, allan_deviation
from accelcal_rig.fit.calibration import ACCELERATION, ANGULAR_RATE, GyroCalibration, load_calibration
from accelcal_rig.fit.campaign_fit import (
    DutFitResult,
    FitOptions,
    fit_dut,
    fit_gyroscope,
    not_calibrated,
    partial_campaign,
)
from accelcal_rig.fit.gyro_acceptance import judge_gyro
from accelcal_rig.fit.gyro_fit import GyroFitResult
from accelcal_rig.fit.noise_record import NOISE_KIND, QUOTED_AT_C, noise_allan
from accelcal_rig.fit.recorded_options import recorded_options
from accelcal_rig.parts.registry import DEFAULT_PART, known_parts
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.read import DutPoses, campaign_status, dut_description, load_campaign, read_dut_poses
from accelcal_rig.store.records import STATIC_KINDS, StoredEvent


@dataclass(frozen=True)
class SoakRecord:
    label: str
    setpoint_c: float
    outcome: str
    t_s: np.ndarray           # (m,) campaign clock
    chamber_c: np.ndarray     # (m,)
    dut_c: np.ndarray         # (m, D)
    t_reached_s: float
    t_stable_s: float


@dataclass(frozen=True)
class DutReport:
    poses: DutPoses                   # the calibration poses (the verification poses' figures are in the fit's)
    pose_numbers: np.ndarray          # (N,) 1-based pose of the schedule
    fit: DutFitResult | None
    truth_by_setpoint: np.ndarray | None   # (K, 12) simulation truth averaged per setpoint, dry runs only
    judgement: Judgement | None = None     # against the procedure's acceptance limits
    verification: DutPoses | None = None   # the verification poses (never fitted), at every setpoint they were taken


@dataclass(frozen=True)
class NoiseCurves:
    """One channel's Allan deviation per axis from a DUT's still record (the one its figures are quoted at)."""

    channel: str
    setpoint_c: float
    curves: list[AllanCurve]          # per axis, in the channel's unit (g, °/s)
    figures: dict[str, Any]           # the calibration's `allan` entry: random walk and bias instability per axis


@dataclass(frozen=True)
class CampaignData:
    path: Path
    status: dict[str, Any]            # as `rig status --json` shows it
    procedure_path: str
    rig_name: str
    soak_band_c: float                # the procedure's soak band
    options: FitOptions | None       # None: the procedure measures only (fit.mode: none)
    duts: dict[str, DutReport]
    soaks: list[SoakRecord]
    events: list[StoredEvent]
    pose_t_s: np.ndarray              # (N,) first sample of each pose
    no_fit_reason: str                # empty when every DUT was fitted
    gravity_m_s2: float               # the site's, as the rig config stated it
    acceptance: Acceptance            # the procedure's limits
    zero_g_offset_mg: dict[str, float | None]  # per DUT, its part's data sheet range of the 0 g offset
    #: Per DUT, the channels it measured that no channel model calibrates yet, each with why.
    not_calibrated: dict[str, dict[str, str]] = field(default_factory=dict)
    #: Per DUT with a calibrated gyroscope, its calibration (verdict, figures, polynomials and setpoints).
    gyros: dict[str, GyroCalibration] = field(default_factory=dict)
    #: Where the gyroscopes came from: the calibration file beside the campaign, or a fit made here.
    gyro_source: str = ""
    #: Per DUT, its channels' Allan curves from the campaign's still record.
    noise: dict[str, list[NoiseCurves]] = field(default_factory=dict)


def read_campaign_data(path: Path) -> CampaignData:
    campaign = load_campaign(path)
    status = campaign_status(path, campaign)
    attrs = campaign.attrs
    procedure = parse_yaml_text(campaign.header.procedure_yaml, f"{path}: its stored procedure")
    soak = procedure.get("soak") if isinstance(procedure, dict) else None
    band_c = float(soak.get("band_c", SoakCriterion().band_c)) if isinstance(soak, dict) else SoakCriterion().band_c
    options = recorded_options(attrs, str(path))
    pose_numbers = campaign.pose_column("pose_number")
    keys = campaign.pose_column("step_key")
    if len(keys):  # the accelerometer's poses are those at rest (read_dut_poses): their numbers likewise
        pose_numbers = pose_numbers[np.isin(keys, list(campaign.header.plan.keys_of(*STATIC_KINDS)))]
    damaged = campaign.unusable_reasons()
    limits = recorded_acceptance(campaign.header.procedure_yaml, str(path))
    partial = partial_campaign(campaign)
    duts, reasons = {}, []
    for serial in campaign.serials:
        stored = read_dut_poses(campaign, serial)
        poses = stored.subset(~stored.verification)
        fit, judgement = None, None
        if options is None:
            reasons.append("the procedure measures only (fit.mode: none)")
        elif damaged:
            reasons.append(f"damaged measurements: {damaged[0]}")
        elif len(poses.setpoint_c):
            try:
                fit = fit_dut(stored, options)
                judgement = judge(fit.metrics, fit.thermal, options.mode, limits, partial, fit.parameter_u)
            except (ValueError, np.linalg.LinAlgError) as exc:
                reasons.append(str(exc))
        else:
            reasons.append("no poses stored")
        duts[serial] = DutReport(poses, pose_numbers[~stored.verification], fit, _truth_by_setpoint(poses), judgement,
                                 stored.subset(stored.verification))
    soaks = [SoakRecord(name, s.setpoint_c, s.outcome, s.t_s, s.chamber_c, s.dut_c, s.t_reached_s, s.t_stable_s)
             for name, s in zip(campaign.soak_names(), campaign.soaks)]
    events = list(campaign.events)
    soaks.sort(key=lambda s: s.t_reached_s)
    reason = "; ".join(dict.fromkeys(reasons))
    gyros, source = ({}, "") if options is None or damaged else _gyroscopes(path, campaign, options, limits, partial)
    return CampaignData(path, status, str(attrs.get("procedure_path", "")), str(attrs.get("rig_name", "")), band_c,
                        options, duts, soaks, events, campaign.pose_column("t_start_s"), reason,
                        float(attrs.get("gravity_m_s2", STANDARD_GRAVITY_M_S2)), limits,
                        {s: _datasheet_offset_mg(campaign, s) for s in campaign.serials},
                        {s: left for s in campaign.serials
                         if (left := {c: why for c, why in not_calibrated(campaign, s).items()
                                      if not (c == ANGULAR_RATE and s in gyros)})},
                        gyros, source, {} if damaged else _noise_curves(campaign, gyros))


def _gyroscopes(path: Path, campaign: Campaign, options: FitOptions, limits: Acceptance,
                partial: str) -> tuple[dict[str, GyroCalibration], str]:
    """Each DUT's gyroscope calibration: from the calibration file beside the campaign (FILE.calibration.yaml)
    when it was fitted to the measurements the campaign holds now, else fitted and judged here as `rig fit`
    would (the file is only read)."""
    beside = path.with_suffix(".calibration.yaml")
    if beside.is_file():
        try:
            calibration = load_calibration(beside)
        except (RigError, OSError):
            calibration = None
        if calibration is not None and calibration.source.get("measurements_sha256") == measurements_sha256(campaign):
            return calibration.gyroscopes, f"the calibration file beside the campaign ({beside.name})"
    gyros = {}
    for serial in campaign.serials:
        try:
            fitted = fit_gyroscope(campaign, serial, options)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if not isinstance(fitted, GyroFitResult):
            continue
        verdict = judge_gyro(fitted.metrics, fitted.thermal, limits, partial, fitted.parameter_u)
        odr_hz = float(campaign.header.duts[campaign.serials.index(serial)].get("odr_hz") or 0.0)
        allan = noise_allan(campaign, serial, ANGULAR_RATE, odr_hz) if odr_hz > 0 else None
        gyros[serial] = fitted.calibration.model_copy(update={
            "verdict": verdict.verdict, "verdict_reasons": verdict.reasons,
            "metrics": {**fitted.calibration.metrics, **({"allan": allan} if allan else {})}})
    return gyros, "fitted from the campaign for this report (no calibration file beside it of these measurements)"


def _noise_curves(campaign: Campaign, gyros: dict[str, GyroCalibration]) -> dict[str, list[NoiseCurves]]:
    """Each DUT's accelerometer and gyroscope Allan curves from the still record nearest 25 °C, beside the
    figures the fit read off them (where it has them)."""
    keys = campaign.pose_column("step_key") if campaign.poses else np.zeros(0, dtype=str)
    noise = np.isin(keys, list(campaign.header.plan.keys_of(NOISE_KIND)))
    if not noise.any():
        return {}
    setpoints, starts = campaign.pose_column("setpoint_c"), campaign.pose_column("t_start_s")
    quoted = min(dict.fromkeys(setpoints[noise].tolist()), key=lambda s: abs(s - QUOTED_AT_C))
    rows = np.flatnonzero(noise & (setpoints == quoted))
    rows = rows[np.argsort(starts[rows])]
    out: dict[str, list[NoiseCurves]] = {}
    for serial in campaign.serials:
        odr_hz = float(campaign.header.duts[campaign.serials.index(serial)].get("odr_hz") or 0.0)
        names = {c.name for c in campaign.header.dut_channels(serial)}
        for channel in (ACCELERATION, ANGULAR_RATE):
            if channel not in names or odr_hz <= 0:
                continue
            info = campaign.channel_info(serial, channel)
            codes = campaign.channel_column(serial, channel, "raw_codes")[rows]
            try:
                curves = allan_deviation(codes.reshape(-1, codes.shape[-1]) * info.lsb, odr_hz)
            except ValueError:
                continue
            figures = noise_allan(campaign, serial, channel, odr_hz) if channel == ACCELERATION else (
                gyros[serial].metrics.get("allan") if serial in gyros else None)
            out.setdefault(serial, []).append(NoiseCurves(channel, float(quoted), curves, figures or {}))
    return out


def _datasheet_offset_mg(campaign: Campaign, serial: str) -> float | None:
    """The data sheet's 0 g offset range of the DUT's part (None for a part this installation does not know)."""
    name = str(dut_description(campaign, serial).get("part", DEFAULT_PART))
    if name not in known_parts():
        return None
    offset_g = known_parts()[name].channel("accel").zero_offset
    return None if offset_g is None else offset_g * 1000.0


def _truth_by_setpoint(poses: DutPoses) -> np.ndarray | None:
    if poses.truth_parameters is None or not len(poses.setpoint_c):
        return None
    setpoints = list(dict.fromkeys(poses.setpoint_c.tolist()))
    return np.array([poses.truth_parameters[poses.setpoint_c == s].mean(axis=0) for s in setpoints])
