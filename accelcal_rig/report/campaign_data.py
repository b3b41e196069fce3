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
from accelcal_rig.fit.acceptance import Judgement, recorded_acceptance
from accelcal_rig.fit.allan import AllanCurve, allan_deviation
from accelcal_rig.fit.campaign_fit import FitOptions, FittedChannel, fit_channels
from accelcal_rig.fit.channel_model import ChannelFit
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.noise_record import NOISE_KIND, QUOTED_AT_C
from accelcal_rig.fit.recorded_options import recorded_options
from accelcal_rig.fit.vector_model import VectorFitDetail
from accelcal_rig.parts.registry import DEFAULT_PART, known_parts
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import VectorPoses, campaign_status, dut_description, load_campaign
from accelcal_rig.store.records import STATIC_KINDS, StoredEvent

#: The quantity whose poses the report's own figures draw (the paper's: |g| before and after, the pose clouds,
#: Eq. 1's parameters over temperature, the residual drift); every channel's figures are in its table.
DRAWN_QUANTITY = "acceleration"


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
    """A DUT's accelerometer as the report's figures draw it."""

    poses: VectorPoses                # the calibration poses (the verification poses' figures are in the fit's)
    pose_numbers: np.ndarray          # (N,) 1-based pose of the schedule
    fit: ChannelFit | None
    truth_by_setpoint: np.ndarray | None   # (K, 12) simulation truth averaged per setpoint, dry runs only
    judgement: Judgement | None = None     # against the procedure's acceptance limits
    verification: VectorPoses | None = None  # the verification poses (never fitted), at every setpoint they were taken

    @property
    def detail(self) -> VectorFitDetail | None:
        """The Eq. 1 fit's setpoints, fits and compensated poses (None: not fitted)."""
        return None if self.fit is None else self.fit.detail


@dataclass(frozen=True)
class NoiseCurves:
    """One channel's Allan deviation per axis from a DUT's still record (the one its figures are quoted at)."""

    channel: str
    quantity: str
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
    #: Per DUT, the channels it measured that no channel model calibrates, each with why.
    not_calibrated: dict[str, dict[str, str]] = field(default_factory=dict)
    #: Per DUT, every calibrated channel (fitted and judged here as `rig fit` would), by channel.
    channels: dict[str, dict[str, FittedChannel]] = field(default_factory=dict)
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
    if len(keys):  # the accelerometer's poses are those at rest (read_vector_poses): their numbers likewise
        pose_numbers = pose_numbers[np.isin(keys, list(campaign.header.plan.keys_of(*STATIC_KINDS)))]
    damaged = campaign.unusable_reasons()
    limits = recorded_acceptance(campaign.header.procedure_yaml, str(path))
    fitted: dict[str, dict[str, FittedChannel]] = {}
    not_calibrated: dict[str, dict[str, str]] = {}
    reasons: list[str] = []
    if options is None:
        reasons.append("the procedure measures only (fit.mode: none)")
    elif damaged:
        reasons.append(f"damaged measurements: {damaged[0]}")
    elif campaign.poses:
        try:
            found = fit_channels(campaign, options, str(path))
            fitted, not_calibrated = found.fitted, {s: left for s, left in found.uncalibrated.items() if left}
        except (ValueError, np.linalg.LinAlgError) as exc:
            reasons.append(str(exc))
    else:
        reasons.append("no poses stored")
    duts = {}
    for serial in campaign.serials:
        info = campaign.channel_of(serial, DRAWN_QUANTITY)
        if info is None:
            continue
        model = model_for_quantity(DRAWN_QUANTITY)
        assert model is not None
        stored = model.records(campaign, info, serial, options or FitOptions()).poses
        drawn = fitted.get(serial, {}).get(info.name)
        if drawn is None and options is not None and not damaged and campaign.poses and not reasons:
            reasons.append(f"sensor {serial}: {not_calibrated.get(serial, {}).get(info.name, 'not fitted')}")
        poses = stored.subset(~stored.verification)
        duts[serial] = DutReport(poses, pose_numbers[~stored.verification], None if drawn is None else drawn.fit,
                                 _truth_by_setpoint(poses), None if drawn is None else drawn.judgement,
                                 stored.subset(stored.verification))
    soaks = [SoakRecord(name, s.setpoint_c, s.outcome, s.t_s, s.chamber_c, s.dut_c, s.t_reached_s, s.t_stable_s)
             for name, s in zip(campaign.soak_names(), campaign.soaks)]
    events = list(campaign.events)
    soaks.sort(key=lambda s: s.t_reached_s)
    reason = "; ".join(dict.fromkeys(reasons))
    return CampaignData(path, status, str(attrs.get("procedure_path", "")), str(attrs.get("rig_name", "")), band_c,
                        options, duts, soaks, events, campaign.pose_column("t_start_s"), reason,
                        float(attrs.get("gravity_m_s2", STANDARD_GRAVITY_M_S2)), limits,
                        {s: _datasheet_offset_mg(campaign, s) for s in campaign.serials},
                        not_calibrated, fitted, {} if damaged else _noise_curves(campaign, fitted))


def _noise_curves(campaign: Campaign, fitted: dict[str, dict[str, FittedChannel]]) -> dict[str, list[NoiseCurves]]:
    """Each DUT's Allan curves of every channel whose model quotes noise figures, from the still record nearest
    25 °C, beside the figures the fit read off them (where it has them)."""
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
        for info in campaign.header.dut_channels(serial):
            model = model_for_quantity(info.quantity)
            if model is None or model.noise is None or odr_hz <= 0:
                continue
            values = campaign.channel_values(serial, info.name)[rows]
            try:
                curves = allan_deviation(values.reshape(-1, values.shape[-1]), odr_hz)
            except ValueError:
                continue
            channel = fitted.get(serial, {}).get(info.name)
            figures = channel.allan if channel is not None else None
            out.setdefault(serial, []).append(NoiseCurves(info.name, info.quantity, float(quoted), curves, figures or {}))
    return out


def _datasheet_offset_mg(campaign: Campaign, serial: str) -> float | None:
    """The data sheet's 0 g offset range of the DUT's part (None for a part this installation does not know)."""
    name = str(dut_description(campaign, serial).get("part", DEFAULT_PART))
    if name not in known_parts():
        return None
    channel = next((c for c in known_parts()[name].channels if c.quantity == DRAWN_QUANTITY), None)
    offset_g = None if channel is None else channel.zero_offset
    return None if offset_g is None else offset_g * 1000.0


def _truth_by_setpoint(poses: VectorPoses) -> np.ndarray | None:
    if poses.truth_parameters is None or not len(poses.setpoint_c):
        return None
    setpoints = list(dict.fromkeys(poses.setpoint_c.tolist()))
    return np.array([poses.truth_parameters[poses.setpoint_c == s].mean(axis=0) for s in setpoints])
