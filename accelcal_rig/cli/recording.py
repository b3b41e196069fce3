"""The work behind `rig fit-recording`: a hand-held recording (CSV, or a campaign file's raw samples) read,
its static intervals found, the norm-only fit done (and the gyroscope's, with --gyro-columns) and its
calibration file written."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from accelcal_rig.errors import ConfigError

if TYPE_CHECKING:
    from accelcal_rig.handheld.calibrate import RecordingFit
    from accelcal_rig.handheld.recording import Recording


def calibrate_recording(args: argparse.Namespace) -> tuple[Recording, RecordingFit]:
    """The recording the command names, and its fit (the calibration file written already)."""
    from accelcal_rig.fit.calibration import save_calibration
    from accelcal_rig.handheld.calibrate import fit_recording
    from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals

    if not args.recording.exists():
        raise ConfigError(f"{args.recording}: no such file")
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    if args.output.is_dir():
        raise ConfigError(f"{args.output}: is a folder; name the calibration file to write")
    settings = DetectorSettings(args.window_s, args.init_s, args.threshold_factor, args.min_interval_s)
    recording, serial = _read(args)
    detection = detect_static_intervals(recording.t_s, recording.accel_g, recording.temperature_c, settings,
                                        recording.source)
    gravity = args.gravity_m_s2 if args.gravity_m_s2 is not None else recording.gravity_m_s2
    result = fit_recording(recording, detection, args.parameters, serial, args.temperature_c, gravity)
    save_calibration(result.calibration, args.output)
    return recording, result


def _read(args: argparse.Namespace) -> tuple[Recording, str]:
    """The recording, and the serial its calibration names (--serial, else the source's or the file's name)."""
    from accelcal_rig.handheld.recording import CsvLayout, read_campaign_recording, read_csv_recording
    from accelcal_rig.handheld.time_base import check_time_base

    if args.recording.suffix in (".h5", ".hdf5"):
        if args.gyro_columns:
            raise ConfigError(f"{args.recording}: --gyro-columns: a campaign file's raw samples hold no turns between "
                              "its poses (the turntable moves between them unrecorded): CSV recordings only")
        recording = read_campaign_recording(args.recording, args.serial, args.setpoint)
        return recording, _serial(recording.serial, args)
    layout = CsvLayout.parse_columns(args.columns, gyro=args.gyro_columns, time_unit=args.time_unit,
                                     rate_hz=args.rate_hz, units=args.units, counts_per_g=args.counts_per_g,
                                     zero_code=args.zero_code, gyro_units=args.gyro_units,
                                     counts_per_dps=args.counts_per_dps)
    recording = read_csv_recording(args.recording, layout)
    check_time_base(recording.source, layout.time, layout.time_unit, recording.t_s, args.part)
    return recording, _serial(args.serial, args)


def _serial(given: str | None, args: argparse.Namespace) -> str:
    """The serial the calibration names: given (--serial, a campaign's DUT), else the recording file's name."""
    from accelcal_rig.core.identifiers import checked_serial

    if given:
        return checked_serial(given, "--serial")
    return checked_serial(args.recording.stem, f"{args.recording}: its file name (give --serial)")
