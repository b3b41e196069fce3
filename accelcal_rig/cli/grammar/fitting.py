"""The grammar of the commands that fit: `rig fit` (a campaign's DUTs) and `rig fit-recording` (a hand-held
recording)."""

from __future__ import annotations

import argparse
from pathlib import Path

from accelcal_rig.cli.grammar.common import TEMPERATURE, Commands, command, fail_on_reject, number, registry_option


def add_fit_commands(commands: Commands) -> None:
    """`rig fit | fit-recording`, in this order."""
    _add_fit(commands)
    _add_fit_recording(commands)


def _add_fit(commands: Commands) -> None:
    """Fit a campaign's DUTs."""
    fit = command(commands, "fit", "fit the error model of every DUT and write a calibration file",
                  "LM fit of Eq. 1 at each setpoint, polynomials over the sensor temperature (Eq. 8), metrics. "
                  "The campaign is only read; the calibration file is replaced whole.",
                  "rig fit campaign.h5 -o calibration.yaml --json")
    fit.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    fit.add_argument("-o", "--output", type=Path, required=True, help="calibration file to write (YAML)")
    fit.add_argument("--mode", choices=["reference", "norm-only"], help="default: the procedure's fit.mode")
    fit.add_argument("--degree", type=int, choices=range(0, 7), metavar="0..6",
                     help="polynomial degree (default: the procedure's fit.polynomial_degree)")
    fit.add_argument("--parameters", choices=["all", "bias-scale"], help="default: the procedure's fit.parameters")
    fit.add_argument("--out-of-range", choices=["clamp", "extrapolate"], help="default: the procedure's")
    fit.add_argument("--temperature-model", choices=["per-setpoint", "joint"],
                     help="default: the procedure's fit.temperature_model")
    fit.add_argument("--partial", action="store_true",
                     help="fit a campaign that has not ended (killed, stopped or aborted before its last pose): "
                          "the calibration and its certificates say PARTIAL, nothing is recorded in the registry")
    fit.add_argument("--json", action="store_true", help="print the metrics as one JSON object")
    registry_option(fit)
    fail_on_reject(fit)


def _add_fit_recording(commands: Commands) -> None:
    """Calibrate from a hand-held recording."""
    recording = command(
        commands, "fit-recording", "calibrate from a continuous recording of a sensor turned by hand (no turntable)",
        "Find the static intervals of a continuous recording (windowed variance against a threshold set from "
        "its first, still seconds), fit the norm-only model (|g| = 1 in every interval) and write the same "
        "calibration file as rig fit, for one temperature. The recording is a CSV file (one row per sample) "
        "or a campaign file's raw samples of one sensor at one setpoint. Record at least 9 orientations "
        "(12 or more, every axis up and down) for all 9 parameters, 6 for bias and scale alone. With "
        "--gyro-columns, the gyroscope's bias and g-sensitivity (from the still intervals, G where an F-test asks "
        "for it) and its scale and misalignment K (from the turns between them, against the gravity directions) "
        "are fitted after and written as its gyro channel: turn the sensor a quarter or half turn about tilted "
        "axes between poses (turns about the vertical, and full turns, determine nothing: then K stays nominal "
        "and the reason is said).",
        "rig fit-recording imu-session.csv --columns samples,ax,ay,az --time-unit samples --rate-hz 200 "
        "--units counts --counts-per-g 2048 --gyro-columns gx,gy,gz --gyro-units counts --counts-per-dps 16.4 "
        "-o imu.calibration.yaml")
    recording.add_argument("recording", type=Path, help="CSV file, or a campaign file (.h5)")
    recording.add_argument("-o", "--output", type=Path, required=True, help="calibration file to write (YAML)")
    _csv_layout_options(recording)
    recording.add_argument("--serial", help="sensor name in the calibration (default: the file's name; campaign "
                                            "files: the first DUT)")
    recording.add_argument("--setpoint", type=TEMPERATURE, help="campaign files: the setpoint whose poses to use")
    recording.add_argument("--part", default="unknown", help="the sensor's part, as the registry records it "
                                                             "(adxl355, …; default unknown)")
    registry_option(recording)
    recording.add_argument("--parameters", choices=["all", "bias-scale"], default="all",
                           help="all: bias, scale, non-orthogonality (9); bias-scale: 6 (default all)")
    recording.add_argument("--temperature-c", type=TEMPERATURE, help="the recording's temperature, if it has none")
    recording.add_argument("--gravity-m-s2", type=number(9.7, 9.9, "m/s²"),
                           help="the site's gravity, which |g| is fitted to (default: the standard 9.80665, said so)")
    _detector_options(recording)
    recording.add_argument("--json", action="store_true", help="print the intervals and results as one JSON object")


def _csv_layout_options(recording: argparse.ArgumentParser) -> None:
    """How a CSV recording's columns read."""
    recording.add_argument("--columns", default="time,x,y,z", metavar="TIME,X,Y,Z[,TEMPERATURE]",
                           help="columns by name (the header's) or by number from 1 (with or without a header), "
                                "in this order; comma, semicolon, tab or white space between them (default: "
                                "time,x,y,z)")
    recording.add_argument("--time-unit", choices=["s", "ms", "samples"], default="s", help="of the time column")
    recording.add_argument("--rate-hz", type=number(1e-3, 1e7, "Hz"), help="sample rate, when the time column counts "
                                                                             "samples")
    recording.add_argument("--units", choices=["g", "counts", "m/s2"], default="g", help="of x, y, z (default g)")
    recording.add_argument("--counts-per-g", type=number(1e-6, 1e12),
                           help="with --units counts (ADXL355 at ±2 g: 256000); if not given, taken from the median "
                                "|reading| (the norm-only fit finds each axis's scale)")
    recording.add_argument("--zero-code", type=number(-1e12, 1e12), default=0.0,
                           help="code of 0 g: 0 for signed codes (default), 32768 for a 16-bit offset-binary ADC")
    recording.add_argument("--gyro-columns", metavar="GX,GY,GZ",
                           help="the gyroscope's x, y, z columns, named or numbered as --columns: calibrate it too "
                                "(bias and g-sensitivity from the static intervals, scale and misalignment from the turns between them)")
    recording.add_argument("--gyro-units", choices=["dps", "rad/s", "counts"], default="dps",
                           help="of the gyro columns (default dps, °/s)")
    recording.add_argument("--counts-per-dps", type=number(1e-6, 1e12),
                           help="with --gyro-units counts (ICM-42688-P at ±2000 °/s: 16.4): the nominal sensitivity "
                                "(the fit finds each axis's scale against it)")


def _detector_options(recording: argparse.ArgumentParser) -> None:
    """How the static intervals are found."""
    recording.add_argument("--window-s", type=number(1e-3, 3600, "s"), default=0.5, help="variance window (default "
                                                                                         "0.5 s)")
    recording.add_argument("--init-s", type=number(1e-3, 3600, "s"), default=2.0,
                           help="initial still period that sets the threshold (default 2 s)")
    recording.add_argument("--threshold-factor", type=number(1.0, 1e6), default=10.0,
                           help="threshold = this × the initial period's variance (default 10)")
    recording.add_argument("--min-interval-s", type=number(1e-3, 3600, "s"), default=1.0,
                           help="shortest static interval (default 1 s)")
