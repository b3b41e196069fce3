"""Every export by its `--format` name, for `rig export` and `rig registry export` alike."""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from accelcal_rig.durable import write_text_atomically
from accelcal_rig.errors import ConfigError
from accelcal_rig.export.ardupilot import to_ardupilot_params
from accelcal_rig.export.c_header import to_c_header
from accelcal_rig.export.flight_stack import ACCELEROMETER, GYROSCOPE, StackOptions
from accelcal_rig.export.px4 import to_px4_params
from accelcal_rig.export.tables import to_csv, to_json
from accelcal_rig.fit.calibration import CalibrationFile
from accelcal_rig.fit.channel_model import ChannelModel
from accelcal_rig.fit.channel_models import model_of

FORMATS = ("json", "csv", "c-header", "px4-params", "ardupilot-params")
STACK_FORMATS = ("px4-params", "ardupilot-params")
#: The sensors a flight stack's thermal compensation holds.
STACK_ROLES = (ACCELEROMETER, GYROSCOPE)


@dataclass(frozen=True)
class Exported:
    text: str
    what: str                       # "4 sensors", "sensor ADX355-A001": for the line that says where it went
    notes: tuple[str, ...] = ()     # what the target cannot hold (flight stacks), also in the file's header


def export(calibration: CalibrationFile, format_name: str, options: StackOptions) -> Exported:
    """The calibration as `format_name`; the flight stacks' formats take one sensor and the stack options."""
    stacks = {"px4-params": to_px4_params, "ardupilot-params": to_ardupilot_params}
    if format_name in stacks:
        exported = stacks[format_name](calibration, options)
        left = not_exported(calibration, [exported.serial], format_name)
        return Exported(exported.text, f"sensor {exported.serial}", (*exported.notes, *left))
    if (options.serial, options.instance, options.device_id) != (None, None, None):
        raise ConfigError(f"--serial, --instance and --device-id are for px4-params and ardupilot-params, not {format_name}")
    text = {"json": to_json, "csv": to_csv, "c-header": to_c_header}[format_name](calibration)
    return Exported(text, f"{len(calibration.duts)} sensors",
                    tuple(not_exported(calibration, calibration.duts, format_name)))


def not_exported(calibration: CalibrationFile, serials: Iterable[str], format_name: str = "") -> list[str]:
    """The channels of these DUTs an export leaves out, each with why: json, csv and the c-header hold every
    calibrated channel (the c-header every one whose model has C code); a flight stack's file the channels its
    thermal compensation has a place for; a channel no model calibrated is in none."""
    uncalibrated = calibration.not_calibrated()
    notes = []
    for serial in serials:
        notes += [f"sensor {serial}: its {channel} channel is not in this export: not calibrated ({why})"
                  for channel, why in uncalibrated.get(serial, {}).items()
                  if channel not in calibration.duts[serial].channels]
        for channel, calibrated in calibration.duts[serial].channels.items():
            model = model_of(calibrated)
            why = _left_out(model, format_name)
            if why:
                notes.append(f"sensor {serial}: its {channel} channel (calibrated, model {calibrated.model}) is not in "
                             f"this {format_name} export: {why}")
    return notes


def _left_out(model: ChannelModel, format_name: str) -> str:
    """Why an export cannot hold a calibrated channel of this model ("": it holds it)."""
    if format_name == "c-header" and model.c_export is None:
        return f"the {model.sensor} model has no C code (the json export carries it)"
    if format_name in STACK_FORMATS and (model.flight_stack is None or model.flight_stack.role not in STACK_ROLES):
        return f"the flight stack's thermal compensation has no place for a {model.sensor} (the json export carries it)"
    return ""


def write_export(exported: Exported, format_name: str, output: Path | None) -> int:
    """Its notes on stderr (what the target cannot hold), the text to `output` or stdout; the exit code."""
    for note in exported.notes:
        print(f"rig: warning: {note}", file=sys.stderr)
    if output is None:
        sys.stdout.write(exported.text)
        return 0
    write_text_atomically(output, exported.text, f"the {format_name} export")
    print(f"{format_name} of {exported.what} → {output}")
    return 0
