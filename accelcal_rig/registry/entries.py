"""A registry entry per DUT of a finished fit: who (serial, part), what (the fit, its validity, verdict and
figures), from what (the source file and its SHA-256, procedure, rig, software) and when: `calibrated_at`
is when the sensor was measured (the campaign's end, a recording's time), `fitted_at` when the fit was made
(a refit of an old campaign is not a newer calibration)."""

from __future__ import annotations

import hashlib
import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import (
    ACCELERATION,
    FORMAT_VERSION,
    CalibrationFile,
    GyroCalibration,
    SensorCalibration,
    load_calibration,
)
from accelcal_rig.registry.figures import channel_figures
from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.read import load_campaign

#: Campaign states whose fit is final: a running campaign's file is still being written.
FINISHED_STATES = ("done", "aborted")
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
        raise ConfigError(f"{campaign_path}: campaign is {campaign.state}, not finished: register it when it ends")
    calibration = load_calibration(calibration_path)
    if calibration.source.get("measurements_sha256") != measurements_sha256(campaign):
        raise ConfigError(f"{calibration_path}: fitted to other measurements than {campaign_path} holds (its "
                          f"measurements_sha256 differs): fit this campaign (rig fit {campaign_path} -o CAL)")
    parts = {str(d["serial"]): str(d.get("part", "unknown")) for d in campaign.header.duts}
    lots = {str(d["serial"]): str(d.get("lot") or "") or None for d in campaign.header.duts}  # absent before 0007
    source = {"kind": "campaign", "path": str(campaign_path.resolve()), "sha256": file_sha256(campaign_path),
              "procedure": str(campaign.attrs.get("procedure_name", "")), "rig": str(campaign.attrs.get("rig_name", "")),
              "simulated": bool(campaign.attrs.get("dry_run", False)),
              "measured": campaign.finished or campaign.header.created}
    return [{**_entry(calibration, channel, sensor, parts.get(serial, "unknown"), source), "lot": lots.get(serial)}
            for serial, dut in calibration.duts.items() for channel, sensor in dut.channels.items()]


def recording_entries(recording_path: Path, calibration: CalibrationFile, part: str,
                      simulated: bool = False) -> list[dict[str, Any]]:
    """The entry of a hand-held fit: its recording is the source (`simulated`: a dry run's campaign file)."""
    measured = datetime.fromtimestamp(recording_path.stat().st_mtime, UTC).isoformat()  # when it was recorded
    source = {"kind": "recording", "path": str(recording_path.resolve()), "sha256": file_sha256(recording_path),
              "procedure": "hand-held", "rig": "hand-held", "simulated": simulated, "measured": measured}
    return [{**_entry(calibration, ACCELERATION, sensor, part, source), "lot": None}
            for sensor in calibration.sensors.values()]


def _entry(calibration: CalibrationFile, channel: str, sensor: SensorCalibration | GyroCalibration, part: str,
           source: dict[str, Any]) -> dict[str, Any]:
    stored = {"file": {"format": calibration.format, "format_version": calibration.format_version,
                       "model": calibration.model, "created": calibration.created,
                       "software_version": calibration.software_version, "source": calibration.source},
              "sensor": json.loads(sensor.model_dump_json())}
    verification = sensor.metrics.get("verification") if isinstance(sensor.metrics.get("verification"), dict) else {}
    rmse = verification.get("rmse_mg") if verification and channel == ACCELERATION else None
    return {
        "serial": sensor.serial, "channel": channel, "part": part, "source_kind": source["kind"],
        "source_path": source["path"],
        "source_sha256": source["sha256"],
        "fit_sha256": hashlib.sha256(json.dumps(stored["sensor"], sort_keys=True).encode()).hexdigest(),
        "procedure": source["procedure"], "rig": source["rig"], "simulated": source["simulated"],
        "software_version": calibration.software_version, "calibrated_at": _utc(source["measured"]),
        "fitted_at": _utc(calibration.created), "registered_at": datetime.now(UTC).replace(tzinfo=None),
        "valid_from_c": float(sensor.validity_c[0]), "valid_to_c": float(sensor.validity_c[1]),
        "verdict": sensor.verdict if sensor.verdict in STORED_VERDICTS else None,
        "verdict_reasons": list(sensor.verdict_reasons),
        "verification_rmse_mg": float(rmse) if rmse is not None else None,
        "calibration": stored, **channel_figures(stored, channel),
    }


def _utc(timestamp: str) -> datetime:
    """An ISO 8601 time as naive UTC (how the registry stores every time)."""
    moment = datetime.fromisoformat(timestamp)
    return (moment.astimezone(UTC) if moment.tzinfo else moment).replace(tzinfo=None)


def calibration_file_of(row: dict[str, Any]) -> CalibrationFile:
    """A registered calibration as a one-sensor calibration file again (for `rig registry export`): the
    channel it is, in the current format whatever format it was fitted in."""
    stored = row["calibration"]
    channels = {row.get("channel") or ACCELERATION: stored["sensor"]}
    return CalibrationFile.model_validate({**stored["file"], "format_version": FORMAT_VERSION,
                                           "duts": {row["serial"]: {"channels": channels}}})
