"""A registry entry per DUT of a finished fit: who (serial, part), what (the fit, its validity, verdict and
figures), from what (the source file and its SHA-256, procedure, rig, software) and when: `calibrated_at`
is when the sensor was measured (the end of the campaign's measurements, a recording's time), `fitted_at` when the fit was made
(a refit of an old campaign is not a newer calibration)."""

from __future__ import annotations

import hashlib
import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from accelcal_rig.core.identifiers import checked_serial
from accelcal_rig.engine.states import State, entered_at
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import (
    FORMAT_VERSION,
    VERSION_1_CHANNEL,
    CalibrationFile,
    ChannelCalibration,
    load_calibration,
)
from accelcal_rig.fit.channel_models import model_of
from accelcal_rig.fit.parameter_uncertainty import reference_c
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.read import load_campaign

#: Campaign states whose fit is recorded: a running campaign's file is still being written, and an aborted one
#: stopped before its last pose (a fit of it is partial: never a serial's calibration).
FINISHED_STATES = ("done",)
#: The verdicts stored as they are (CONDITIONAL: a limit met or missed inside its guard band under guarded
#: acceptance); any other (NOT JUDGED: no limits stated) is stored as none, counted in no yield.
STORED_VERDICTS = ("PASS", "FAIL", "CONDITIONAL")


def file_sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as stream:
        for chunk in iter(lambda: stream.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def campaign_entries(campaign_path: Path, calibration_path: Path | None = None) -> list[dict[str, Any]]:
    """One entry per calibrated channel of each DUT of a campaign file and its calibration (by default the one
    `rig run`/`rig fit` writes beside it, FILE.calibration.yaml): an IMU's accelerometer and its gyroscope."""
    calibration_path = calibration_path or campaign_path.with_suffix(".calibration.yaml")
    if not calibration_path.is_file():
        raise ConfigError(f"{campaign_path}: no calibration beside it ({calibration_path.name}): fit it first "
                          f"(rig fit {campaign_path} -o {calibration_path})")
    campaign = load_campaign(campaign_path)
    if campaign.state not in FINISHED_STATES:
        why = f" ({campaign.abort_reason})" if campaign.state == "aborted" and campaign.abort_reason else ""
        raise ConfigError(f"{campaign_path}: campaign is {campaign.state}{why}, {len(campaign.poses)} of "
                          f"{campaign.poses_planned} poses stored: nothing is recorded from half a campaign (rig "
                          f"resume {campaign_path} finishes it)")
    calibration = load_calibration(calibration_path)
    if calibration.source.get("measurements_sha256") != measurements_sha256(campaign):
        raise ConfigError(f"{calibration_path}: fitted to other measurements than {campaign_path} holds (its "
                          f"measurements_sha256 differs): fit this campaign (rig fit {campaign_path} -o CAL)")
    parts = {str(d["serial"]): str(d.get("part", "unknown")) for d in campaign.header.duts}
    lots = {str(d["serial"]): str(d.get("lot") or "") or None for d in campaign.header.duts}  # absent before 0007
    source = {"kind": "campaign", "path": str(campaign_path.resolve()), "sha256": file_sha256(campaign_path),
              "procedure": str(campaign.attrs.get("procedure_name", "")), "rig": str(campaign.attrs.get("rig_name", "")),
              "simulated": bool(campaign.attrs.get("dry_run", False)),
              "measured": measured_at(campaign)}
    return [{**_entry(calibration, channel, calibrated, parts.get(serial, "unknown"), source), "lot": lots.get(serial)}
            for serial, channel, calibrated in calibration.calibrated()]


def recording_entries(recording_path: Path, calibration: CalibrationFile, part: str,
                      simulated: bool = False) -> list[dict[str, Any]]:
    """The entry of a hand-held fit: its recording is the source (`simulated`: a dry run's campaign file)."""
    measured = datetime.fromtimestamp(recording_path.stat().st_mtime, UTC).isoformat()  # when it was recorded
    source = {"kind": "recording", "path": str(recording_path.resolve()), "sha256": file_sha256(recording_path),
              "procedure": "hand-held", "rig": "hand-held", "simulated": simulated, "measured": measured}
    return [{**_entry(calibration, channel, calibrated, part, source), "lot": None}
            for _, channel, calibrated in calibration.calibrated()]


def _entry(calibration: CalibrationFile, channel: str, sensor: ChannelCalibration, part: str,
           source: dict[str, Any]) -> dict[str, Any]:
    stored = {"file": {"format": calibration.format, "format_version": calibration.format_version,
                       "created": calibration.created, "software_version": calibration.software_version,
                       "source": calibration.source},
              "sensor": json.loads(sensor.model_dump_json())}
    return {
        "serial": checked_serial(sensor.serial, f"{source['path']}: its calibration"), "channel": channel, "part": part,
        "source_kind": source["kind"],
        "source_path": source["path"],
        "source_sha256": source["sha256"],
        "fit_sha256": hashlib.sha256(json.dumps(stored["sensor"], sort_keys=True).encode()).hexdigest(),
        "procedure": source["procedure"], "rig": source["rig"], "simulated": source["simulated"],
        "software_version": calibration.software_version, "calibrated_at": _utc(source["measured"]),
        "fitted_at": _utc(calibration.created), "registered_at": datetime.now(UTC).replace(tzinfo=None),
        "valid_from_c": float(sensor.validity_c[0]), "valid_to_c": float(sensor.validity_c[1]),
        "verdict": sensor.verdict if sensor.verdict in STORED_VERDICTS else None,
        "verdict_reasons": list(sensor.verdict_reasons),
        "calibration": stored, "reference_c": reference_c(sensor.validity_c),
        "figures": [{"name": f.name, "label": f.label, "unit": f.unit, "axes": "xyz" if len(f.values) == 3 else "",
                     "value": list(f.values), "expanded_u": None if f.expanded is None else list(f.expanded),
                     "trend": f.trend, "lot": f.lot} for f in model_of(sensor).stored_figures(sensor)],
    }


def measured_at(campaign: Campaign) -> str:
    """When the campaign's measurements ended: where the run went on to fit them (the journal's transition into
    the fit stage), that moment, since the campaign is only marked finished after its fit; else its end."""
    into_fit = entered_at(campaign.events, State.FIT)
    return (into_fit[-1] if into_fit else "") or campaign.finished or campaign.header.created


def _utc(timestamp: str) -> datetime:
    """An ISO 8601 time as naive UTC (how the registry stores every time)."""
    moment = datetime.fromisoformat(timestamp)
    return (moment.astimezone(UTC) if moment.tzinfo else moment).replace(tzinfo=None)


def calibration_file_of(rows: list[dict[str, Any]]) -> CalibrationFile:
    """Registered calibrations of one sensor (each of a channel) as a one-sensor calibration file again (for `rig
    registry export`), in the current format whatever format each was fitted in (the first's file facts)."""
    stored = rows[0]["calibration"]
    channels = {row.get("channel") or VERSION_1_CHANNEL: row["calibration"]["sensor"] for row in rows}
    file = {k: v for k, v in stored["file"].items() if k != "model"}  # a file-wide model: versions 1 and 2
    return CalibrationFile.model_validate({**file, "format_version": FORMAT_VERSION,
                                           "duts": {rows[0]["serial"]: {"channels": channels}}})
