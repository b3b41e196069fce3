"""Everything a campaign report shows, read from the campaign file and fitted in memory.

The fit is redone here with the options the file records (the same result `rig fit` writes, the file is
only read), so a report works on a finished, an aborted or a still running campaign alike; when there
are too few poses to fit, the report shows what was measured and says why there is no fit.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from accelcal_rig.config.procedure import SoakCriterion
from accelcal_rig.fit.campaign_fit import DutFitResult, FitOptions, fit_dut
from accelcal_rig.store.read import DutPoses, campaign_status, open_campaign, read_dut_poses


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
class EventRecord:
    t_s: float
    wall_time: str
    level: str
    kind: str
    message: str


@dataclass(frozen=True)
class DutReport:
    poses: DutPoses
    pose_numbers: np.ndarray          # (N,) 1-based pose of the schedule
    fit: DutFitResult | None
    truth_by_setpoint: np.ndarray | None   # (K, 12) simulation truth averaged per setpoint, dry runs only


@dataclass(frozen=True)
class CampaignData:
    path: Path
    status: dict[str, Any]            # as `rig status --json` shows it
    procedure_path: str
    rig_name: str
    soak_band_c: float                # the procedure's soak band
    options: FitOptions
    duts: dict[str, DutReport]
    soaks: list[SoakRecord]
    events: list[EventRecord]
    pose_t_s: np.ndarray              # (N,) first sample of each pose
    no_fit_reason: str                # empty when every DUT was fitted


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def read_campaign_data(path: Path) -> CampaignData:
    status = campaign_status(path)
    with open_campaign(path) as file:
        attrs = file.attrs
        procedure = yaml.safe_load(_text(file["config/procedure_yaml"][()])) or {}
        band_c = float((procedure.get("soak") or {}).get("band_c", SoakCriterion().band_c))
        options = FitOptions(mode=str(attrs.get("fit_mode", "reference")), degree=int(attrs.get("polynomial_degree", 3)),
                             free=str(attrs.get("fit_parameters", "all")),  # type: ignore[arg-type]
                             out_of_range=str(attrs.get("fit_out_of_range", "clamp")),  # type: ignore[arg-type]
                             temperature_model=str(attrs.get("fit_temperature_model", "per-setpoint")))  # type: ignore[arg-type]
        pose_numbers = file["poses/pose_number"][:]
        duts, reasons = {}, []
        for serial in file["duts"]:
            poses = read_dut_poses(file, serial)
            fit = None
            if options.mode == "none":
                reasons.append("the procedure measures only (fit.mode: none)")
            elif len(poses.setpoint_c):
                try:
                    fit = fit_dut(poses, options)
                except (ValueError, np.linalg.LinAlgError) as exc:
                    reasons.append(str(exc))
            else:
                reasons.append("no poses stored")
            duts[serial] = DutReport(poses, pose_numbers, fit, _truth_by_setpoint(poses))
        soaks = [
            SoakRecord(label, float(g.attrs["setpoint_c"]), _text(g.attrs["outcome"]), g["t_s"][:], g["chamber_c"][:],
                       g["dut_c"][:], float(g.attrs["t_reached_s"]), float(g.attrs["t_stable_s"]))
            for label, g in file.get("soaks", {}).items()
        ]
        events_group = file["events"]
        events = [EventRecord(float(t), _text(w), _text(lv), _text(k), _text(m)) for t, w, lv, k, m in zip(
            events_group["t_s"][:], events_group["wall_time"][:], events_group["level"][:], events_group["kind"][:],
            events_group["message"][:])]
        pose_t_s = file["poses/t_start_s"][:]
        procedure_path, rig_name = _text(attrs.get("procedure_path", "")), _text(attrs.get("rig_name", ""))
    soaks.sort(key=lambda s: s.t_reached_s)
    reason = "; ".join(dict.fromkeys(reasons))
    return CampaignData(path, status, procedure_path, rig_name, band_c, options, duts, soaks, events, pose_t_s, reason)


def _truth_by_setpoint(poses: DutPoses) -> np.ndarray | None:
    if poses.truth_parameters is None or not len(poses.setpoint_c):
        return None
    setpoints = list(dict.fromkeys(poses.setpoint_c.tolist()))
    return np.array([poses.truth_parameters[poses.setpoint_c == s].mean(axis=0) for s in setpoints])
