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
from accelcal_rig.export.flight_stack import StackOptions
from accelcal_rig.export.px4 import to_px4_params
from accelcal_rig.export.tables import to_csv, to_json
from accelcal_rig.fit.calibration import CalibrationFile

FORMATS = ("json", "csv", "c-header", "px4-params", "ardupilot-params")


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
    return Exported(text, f"{len(calibration.sensors)} sensors",
                    tuple(not_exported(calibration, calibration.sensors, format_name)))


#: The formats that leave a calibrated gyroscope out (every other one carries it beside the accelerometer).
WITHOUT_GYRO = {"csv": "the json export and the c-header carry it"}


def not_exported(calibration: CalibrationFile, serials: Iterable[str], format_name: str = "") -> list[str]:
    """The channels of these DUTs an export leaves out, each with why: every export holds the accel channel, and
    every one but csv a calibrated gyro channel; a channel no model calibrated is in none."""
    uncalibrated = calibration.not_calibrated()
    gyroscopes = calibration.gyroscopes
    notes = []
    for serial in serials:
        notes += [f"sensor {serial}: its {channel} channel is not in this export: not calibrated ({why})"
                  for channel, why in uncalibrated.get(serial, {}).items()
                  if channel not in calibration.duts[serial].channels]
        if serial in gyroscopes and format_name in WITHOUT_GYRO:
            notes.append(f"sensor {serial}: its gyro channel (calibrated, model gyro-rate-table) is not in this "
                         f"{format_name} export: {WITHOUT_GYRO[format_name]}")
    return notes


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
