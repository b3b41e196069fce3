"""`rig fit` on a campaign file: the fit's adapter from a file on disk to a calibration file beside it.

Everything the command refuses is refused here in one line: a campaign a run holds (fit it once it is
done), damaged measurements, a procedure that asked for no fit and no mode given, a folder as output.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from accelcal_rig.errors import ConfigError, RigError
from accelcal_rig.fit.acceptance import NOT_JUDGED, Judgement
from accelcal_rig.fit.calibration import CalibrationFile, load_calibration
from accelcal_rig.fit.campaign_fit import dut_verdict, fit_and_save
from accelcal_rig.fit.recorded_options import recorded_options
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.lock import holder
from accelcal_rig.store.read import load_campaign, usable_campaign


@dataclass(frozen=True)
class FitOutcome:
    report: dict[str, Any]    #: per sensor serial, as `rig fit --json` prints it
    warnings: list[str]       #: for the operator, one line each
    ended: bool = True        #: the campaign had ended (done): else a partial fit, never recorded


def fit_campaign_file(path: Path, output: Path, partial: bool = False, **overrides: Any) -> FitOutcome:
    """The campaign at `path` fitted with the options it records (any `overrides` not None instead: mode,
    degree, free, out_of_range, temperature_model), its calibration written to `output`; the campaign is
    only read. A campaign that has not ended (not `done`) is refused in one line unless `partial`: nothing is
    recorded from half a campaign."""
    running = holder(path)
    if running is not None:
        raise ConfigError(f"{path}: a campaign is running on it, {running}: fit it once it is done")
    campaign = usable_campaign(path)
    if campaign.state != "done" and not partial:
        raise ConfigError(f"{path}: {unfinished(campaign)}: rig resume {path} finishes it (rig fit --partial fits "
                          "what is stored, never recorded in the registry)")
    warnings = [f"{path}: {note}" for note in campaign.notes]
    options = recorded_options(campaign.attrs, str(path), **overrides)
    if options is None:
        raise ConfigError(f"{path}: its procedure asked for no fit (fit.mode: none); choose one with "
                          "--mode reference or --mode norm-only")
    if output.is_dir():
        raise ConfigError(f"{output}: is a folder; name the calibration file to write")
    try:
        fitted, report = fit_and_save(campaign, path, output, options)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise RigError(f"{path}: fit failed: {str(exc).splitlines()[0]}") from None
    warnings += [f"sensor {serial}: not fitted: {why}" for serial, why in fitted.dropped.items()]
    if campaign.state != "done":
        warnings.append(f"a partial fit of a campaign that has not ended ({unfinished(campaign)}): its calibration "
                        "and certificates say PARTIAL; it is not recorded in the registry")
    return FitOutcome(report, warnings, ended=campaign.state == "done")


def unfinished(campaign: Campaign) -> str:
    """What a campaign that has not ended lacks, in a few words: its state and the poses still to measure."""
    stored, planned = len(campaign.poses), campaign.poses_planned
    missing = [key for key in campaign.header.plan.pose_keys if key not in campaign.stored_keys]
    why = f" ({campaign.abort_reason})" if campaign.state == "aborted" and campaign.abort_reason else ""
    return (f"the campaign is {campaign.state}{why}, {stored} of {planned} poses stored"
            + (f", next {missing[0]}" if missing else ""))


def calibration_verdicts(campaign_path: Path, calibration_path: Path | None = None,
                         campaign: Campaign | None = None) -> dict[str, Any]:
    """What `rig status` says of a campaign's calibration: the file (default beside the campaign), whether it
    was fitted to the measurements the campaign holds now, and each DUT's verdict with its reasons.
    `campaign`: the campaign read already (a reader that has it need not read it twice)."""
    path = calibration_path or campaign_path.with_suffix(".calibration.yaml")
    if not path.is_file():
        return {"calibration": None, "verdicts": None}
    try:
        calibration = load_calibration(path)
    except ConfigError as exc:
        return {"calibration": f"{path}: unreadable: {str(exc).splitlines()[0]}", "verdicts": None}
    fitted = calibration.source.get("measurements_sha256")
    current = fitted == measurements_sha256(campaign if campaign is not None else load_campaign(campaign_path))
    partial = calibration.source.get("partial")
    return {
        "calibration": f"{path}" + ("" if current else " (fitted to other measurements than the campaign's now: "
                                                       "fit again)") + (f"; {partial}" if partial else ""),
        "verdicts": {serial: {"verdict": judged.verdict, "reasons": judged.reasons,
                              "sensors": sensor_verdicts(calibration, serial)}
                     for serial, judged in dut_verdicts(calibration).items()},
    }


def sensor_verdicts(calibration: CalibrationFile, serial: str) -> dict[str, str]:
    """Each calibrated sensor's own verdict of a DUT, by the sensor's name ("accelerometer", "gyroscope"): an
    IMU's page shows both, not only the DUT's combined one."""
    from accelcal_rig.fit.channel_models import model_of

    return {model_of(channel).sensor: channel.verdict or NOT_JUDGED
            for channel in calibration.duts[serial].channels.values()}


def dut_verdicts(calibration: CalibrationFile) -> dict[str, Judgement]:
    """Each DUT's verdict and reasons from its channels' as the calibration file keeps them."""
    return {serial: dut_verdict([(name, Judgement(channel.verdict or NOT_JUDGED, list(channel.verdict_reasons)))
                                 for name, channel in dut.channels.items()])
            for serial, dut in calibration.duts.items()}
