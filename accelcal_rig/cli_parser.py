"""The `rig` command line's grammar: every subcommand, option and its bounds, and --help's examples.

Parsing imports nothing heavy: `rig --help` and a mistyped option answer at once.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

from accelcal_rig import __version__

FAULTS_HELP = ("fault injection into the simulators, e.g. rate=0.05,kinds=drop+corrupt or "
               "chamber_stall_after_min=60 (keys of simulation.faults)")


class _Parser(argparse.ArgumentParser):
    """Command-line mistakes are one line too (argparse would print its usage above them)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _number(low: float, high: float, unit: str = "", integer: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number within [low, high]."""
    def parse(text: str) -> float:
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a{'' if integer else ' finite'} number") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"{text} is outside {low:g} … {high:g}{' ' + unit if unit else ''}")
        return value
    return parse


_TEMPERATURE = _number(-100.0, 300.0, "°C")
_SEED = _number(0, 2**32 - 1, integer=True)


def _command(commands: argparse._SubParsersAction, name: str, summary: str, description: str,
             example: str) -> argparse.ArgumentParser:
    """A subcommand whose --help ends with an example."""
    return commands.add_parser(name, help=summary, description=description, epilog=f"example:\n  {example}",
                               formatter_class=argparse.RawDescriptionHelpFormatter)


def _campaign_output_options(command: argparse.ArgumentParser) -> None:
    """What `rig run` and `rig resume` share: where the fit writes, and how much the console says."""
    command.add_argument("--calibration", type=Path,
                         help="calibration file the final fit writes (default: beside the campaign, .calibration.yaml)")
    command.add_argument("-v", "--verbose", action="store_true", help="log every transition and pose")
    command.add_argument("-q", "--quiet", action="store_true", help="print only warnings and the summary")
    _fail_on_reject(command)
    command.add_argument("--certificates", type=Path, help="folder of the DUTs' certificates written after the fit "
                                                            "(default: beside the campaign, .certificates)")
    _certificate_options(command)
    registry_option(command)


def _certificate_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("--operator", default="", help="who performed the calibration (on the certificates)")
    command.add_argument("--no-pdf", action="store_true", help="HTML certificates only")


def _fail_on_reject(command: argparse.ArgumentParser) -> None:
    command.add_argument("--fail-on-reject", action="store_true",
                         help="exit with status 3 when any DUT fails the procedure's acceptance limits")


REGISTRY_HELP = ("the registry: a postgresql:// URL or an SQLite file (default: the rig config's registry:, "
                 "else $ACCELCAL_REGISTRY, else ~/.local/share/accelcal-rig/registry.sqlite)")


def registry_option(command: argparse.ArgumentParser) -> None:
    """`--registry URL`: the same on every command that records or reads calibrations."""
    command.add_argument("--registry", metavar="URL", help=REGISTRY_HELP)


def _registry_commands(commands: argparse._SubParsersAction) -> None:
    registry = _command(commands, "registry", "the lab's calibrations by serial number: add, list, show, export, "
                        "trend, stats",
                        "Every finished fit is recorded by DUT serial: rig run, rig fit and rig fit-recording do it "
                        "themselves; rig registry add records campaigns fitted before (idempotent: the same "
                        "file again adds nothing). The database is an SQLite file by default, or PostgreSQL for "
                        "several rigs (see docs/registry.md).",
                        "rig registry show ADX355-A001")
    actions = registry.add_subparsers(dest="registry_command", required=True, metavar="ACTION")

    def action(name: str, summary: str, example: str) -> argparse.ArgumentParser:
        command = _command(actions, name, summary, summary[0].upper() + summary[1:] + ".", example)
        registry_option(command)
        command.add_argument("--config", type=Path, metavar="RIG", help="rig config whose registry: to use")
        return command

    add = action("add", "record finished campaigns and their calibrations", "rig registry add campaign.h5")
    add.add_argument("files", type=Path, nargs="+", metavar="FILE", help="campaign file (HDF5)")
    add.add_argument("--calibration", type=Path, help="its calibration (default: FILE.calibration.yaml beside it)")
    listing = action("list", "calibrations, newest first, filtered", "rig registry list --part adxl355 --since 2026-01-01")
    listing.add_argument("--serial", help="only this DUT")
    listing.add_argument("--part", help="only this part (adxl355, adxl357, …)")
    listing.add_argument("--since", metavar="DATE", help="only those calibrated on or after this date (YYYY-MM-DD)")
    listing.add_argument("--verdict", choices=["PASS", "FAIL"], help="only those with this verdict")
    listing.add_argument("--limit", type=_number(1, 10_000_000, integer=True), help="at most this many")
    listing.add_argument("--json", action="store_true", help="one JSON list")
    show = action("show", "a sensor's valid calibration and its history", "rig registry show ADX355-A001")
    show.add_argument("serial")
    show.add_argument("--json", action="store_true", help="one JSON object")
    show.add_argument("--simulated", action="store_true", help="count dry runs too (left out by default)")
    export = action("export", "a sensor's valid calibration (or one by id) as a file other tools read",
                    "rig registry export ADX355-A001 --format c-header -o accel.h")
    export.add_argument("serial")
    export.add_argument("--format", required=True, choices=["json", "csv", "c-header", "px4-params", "ardupilot-params"],
                        help="what to write (as rig export)")
    export.add_argument("--id", type=_number(1, 2**63 - 1, integer=True), help="this calibration, not the valid one")
    export.add_argument("--instance", type=_number(0, 3, integer=True), help="px4-params, ardupilot-params: as rig export")
    export.add_argument("--device-id", type=_number(1, 2**31 - 1, integer=True), help="px4-params: as rig export")
    export.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    export.add_argument("--simulated", action="store_true", help="count dry runs too (left out by default)")
    trend = action("trend", "bias and scale at the reference temperature across recalibrations: ageing drift",
                   "rig registry trend ADX355-A001")
    trend.add_argument("serial")
    trend.add_argument("--json", action="store_true", help="one JSON object")
    trend.add_argument("--simulated", action="store_true", help="count dry runs too (left out by default)")
    stats = action("stats", "a part's lot: yield, distributions of bias, scale and non-orthogonality, outliers",
                   "rig registry stats --part adxl355")
    stats.add_argument("--part", required=True)
    stats.add_argument("--json", action="store_true", help="one JSON object")
    stats.add_argument("--simulated", action="store_true", help="count dry runs too (left out by default)")


def _analysis_command(analyses: argparse._SubParsersAction, name: str, summary: str, description: str,
                      example: str, *, calibration: bool, figure: bool) -> argparse.ArgumentParser:
    """A `rig analyze` subcommand with the arguments every analysis shares."""
    command = _command(analyses, name, summary, description, example)
    command.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    if calibration:
        command.add_argument("--calibration", type=Path, required=True, help="calibration file (YAML) of the same DUTs")
    command.add_argument("--setpoint", type=_TEMPERATURE, help="the setpoint to analyse (default: the file's only one)")
    if figure:
        command.add_argument("--figure", type=Path, help="write the figure (PNG) here")
    command.add_argument("--json", action="store_true", help="print one JSON object")
    return command


#: The built-in chamber profiles a dry run or `rig sim` may swap in (accelcal_rig.protocols.chamber_registers).
CHAMBER_PROFILE_HELP = ("simulate a chamber of this built-in profile instead of the rig's (watlow-f4, watlow-f4t, "
                        "espec-p300, thermotron-8800, simserv, watlow-f4t-scpi)")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="rig", description="Run MEMS accelerometer calibration campaigns.")
    parser.add_argument("--version", action="version", version=f"accelcal-rig {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = _command(commands, "run", "run a campaign from a procedure file",
                   "Run a campaign: ramp and soak at each setpoint, measure every pose, store pose by pose, "
                   "make the rig safe, fit.",
                   "rig run procedures/paper-24pos-thermal.yaml --dry-run -o campaign.h5")
    run.add_argument("procedure", type=Path, help="procedure YAML file")
    run.add_argument("-o", "--output", type=Path, required=True, help="campaign file to create (HDF5)")
    run.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    run.add_argument("--dry-run", action="store_true", help="simulated rig in virtual time")
    run.add_argument("--seed", type=_SEED, default=0, help="seed of the simulated noise (default 0)")
    run.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    run.add_argument("--chamber-profile", metavar="PROFILE", help=f"with --dry-run: {CHAMBER_PROFILE_HELP}")
    run.add_argument("--overwrite", action="store_true", help="replace an existing campaign file")
    run.add_argument("--resume", action="store_true",
                     help="continue the campaign in the output file if it exists (after a crash, a fault or "
                          "Ctrl-C), else start it")
    _campaign_output_options(run)

    plan = _command(commands, "plan", "validate a procedure, show its schedule and estimate its duration",
                    "Validate the procedure and its rig config, compile the plan and print it: setpoints, soak "
                    "criterion, every pose with its turntable angles and gravity direction, samples, and the "
                    "time each setpoint's ramp, soak and poses will take. Touches no instrument.",
                    "rig plan procedures/paper-24pos-thermal.yaml")
    plan.add_argument("procedure", type=Path, help="procedure YAML file")
    plan.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    plan.add_argument("--json", action="store_true", help="print one JSON object")

    resume = _command(commands, "resume", "continue a campaign that stopped before it was complete",
                      "Continue a campaign from its file: with the procedure it was started with (its path is "
                      "in the file) and the same rig (ports may differ), the rig made safe first if the last "
                      "run died, a fresh soak at the first setpoint with poses missing, then every pose not "
                      "stored yet. A dry run resumes as a dry run.",
                      "rig resume campaign.h5")
    resume.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    resume.add_argument("--procedure", type=Path, help="procedure YAML (default: the path stored in the file)")
    resume.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    resume.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    _campaign_output_options(resume)

    status = _command(commands, "status", "show a campaign file's state and progress",
                      "Show a campaign's state and progress (works on finished, aborted and running files).",
                      "rig status campaign.h5 --json")
    status.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    status.add_argument("--json", action="store_true", help="print one JSON object")
    status.add_argument("--calibration", type=Path, help="its calibration file, for the verdicts (default: beside "
                                                         "the campaign, .calibration.yaml)")
    status.add_argument("--watch", nargs="?", const=2.0, type=_number(0.2, 3600, "s"), metavar="S",
                        help="show it again every S seconds (default 2) until the campaign ends or Ctrl-C")

    repair = _command(commands, "repair", "rebuild a campaign file from its journal",
                      "Bring a campaign's files back in step without losing a record: the campaign file (HDF5) "
                      "rebuilt from its journal; a journal with damaged stretches compacted to its whole records "
                      "(the original kept beside it); a campaign file without a journal given one. Refused while "
                      "a run holds the campaign.",
                      "rig repair campaign.h5")
    repair.add_argument("campaign", type=Path, help="campaign file (HDF5)")

    check = _command(commands, "check", "contact every instrument of a rig and describe each in one line",
                     "Connect to the chamber, the turntable and every sensor of a rig config, check their "
                     "identities and print what they report. Run it before leaving a campaign overnight.",
                     "rig check configs/example-lab.yaml")
    check.add_argument("rig", type=Path, help="rig config YAML")
    check.add_argument("--dry-run", action="store_true", help="check the rig's simulators instead")
    check.add_argument("--only", action="append", choices=["chamber", "turntable", "sensors"],
                       help="check only this instrument (repeat for more); the rig config may then leave out the "
                            "others' sections")
    check.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)

    sim = _command(commands, "sim", "serve the simulated rig as real endpoints until interrupted",
                   "Start the simulated rig of a rig config: the chamber on Modbus TCP or its line protocol "
                   "over TCP (127.0.0.1), the turntable and each sensor bridge on a pseudo-terminal, in real "
                   "time. The first line on "
                   "stdout is one JSON object with the endpoints. Ctrl-C stops it.",
                   "rig sim configs/sim.yaml")
    sim.add_argument("rig", type=Path, help="rig config YAML")
    sim.add_argument("--seed", type=_SEED, default=0, help="seed of the simulated noise (default 0)")
    sim.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    sim.add_argument("--chamber-profile", metavar="PROFILE", help=CHAMBER_PROFILE_HELP)

    fit = _command(commands, "fit", "fit the error model of every DUT and write a calibration file",
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
    fit.add_argument("--json", action="store_true", help="print the metrics as one JSON object")
    registry_option(fit)
    _fail_on_reject(fit)
    recording = _command(
        commands, "fit-recording", "calibrate from a continuous recording of a sensor turned by hand (no turntable)",
        "Find the static intervals of a continuous recording (windowed variance against a threshold set from "
        "its first, still seconds), fit the norm-only model (|g| = 1 in every interval) and write the same "
        "calibration file as rig fit, for one temperature. The recording is a CSV file (one row per sample) "
        "or a campaign file's raw samples of one sensor at one setpoint. Record at least 9 orientations "
        "(12 or more, every axis up and down) for all 9 parameters, 6 for bias and scale alone.",
        "rig fit-recording session.csv --columns samples,acc_x,acc_y,acc_z --time-unit samples --rate-hz 204.8 "
        "--units counts --counts-per-g 2048 --parameters bias-scale -o imu.calibration.yaml")
    recording.add_argument("recording", type=Path, help="CSV file, or a campaign file (.h5)")
    recording.add_argument("-o", "--output", type=Path, required=True, help="calibration file to write (YAML)")
    recording.add_argument("--columns", default="time,x,y,z", metavar="TIME,X,Y,Z[,TEMPERATURE]",
                           help="columns by name (the header's) or by number from 1 (with or without a header), "
                                "in this order; comma, semicolon, tab or white space between them (default: "
                                "time,x,y,z)")
    recording.add_argument("--time-unit", choices=["s", "ms", "samples"], default="s", help="of the time column")
    recording.add_argument("--rate-hz", type=_number(1e-3, 1e7, "Hz"), help="sample rate, when the time column counts "
                                                                              "samples")
    recording.add_argument("--units", choices=["g", "counts", "m/s2"], default="g", help="of x, y, z (default g)")
    recording.add_argument("--counts-per-g", type=_number(1e-6, 1e12),
                           help="with --units counts (ADXL355 at ±2 g: 256000); if not given, taken from the median "
                                "|reading| (the norm-only fit finds each axis's scale)")
    recording.add_argument("--zero-code", type=_number(-1e12, 1e12), default=0.0,
                           help="code of 0 g: 0 for signed codes (default), 32768 for a 16-bit offset-binary ADC")
    recording.add_argument("--serial", help="sensor name in the calibration (default: the file's name; campaign "
                                            "files: the first DUT)")
    recording.add_argument("--setpoint", type=_TEMPERATURE, help="campaign files: the setpoint whose poses to use")
    recording.add_argument("--part", default="unknown", help="the sensor's part, as the registry records it "
                                                             "(adxl355, …; default unknown)")
    registry_option(recording)
    recording.add_argument("--parameters", choices=["all", "bias-scale"], default="all",
                           help="all: bias, scale, non-orthogonality (9); bias-scale: 6 (default all)")
    recording.add_argument("--temperature-c", type=_TEMPERATURE, help="the recording's temperature, if it has none")
    recording.add_argument("--gravity-m-s2", type=_number(9.7, 9.9, "m/s²"),
                           help="the site's gravity, which |g| is fitted to (default: the standard 9.80665, said so)")
    recording.add_argument("--window-s", type=_number(1e-3, 3600, "s"), default=0.5, help="variance window (default "
                                                                                          "0.5 s)")
    recording.add_argument("--init-s", type=_number(1e-3, 3600, "s"), default=2.0,
                           help="initial still period that sets the threshold (default 2 s)")
    recording.add_argument("--threshold-factor", type=_number(1.0, 1e6), default=10.0,
                           help="threshold = this × the initial period's variance (default 10)")
    recording.add_argument("--min-interval-s", type=_number(1e-3, 3600, "s"), default=1.0,
                           help="shortest static interval (default 1 s)")
    recording.add_argument("--json", action="store_true", help="print the intervals and results as one JSON object")

    analyze = _command(commands, "analyze", "the paper's other experiments on a campaign file: positions, tilt, cooldown",
                       "Analyses of campaign files beyond the calibration: how many positions a calibration "
                       "needs (positions), tilt angles before and after calibration (tilt), the temperature "
                       "coefficient during a free cool-down (cooldown).",
                       "rig analyze positions campaign.h5 --figure positions.png")
    analyses = analyze.add_subparsers(dest="analysis", required=True, metavar="ANALYSIS")
    positions = _analysis_command(
        analyses, "positions", "refit on subsets of 1296 … 12 positions, score on the rest",
        "Refit the error model on subsets of the poses of one setpoint, of the sizes of the paper's Table 4 "
        "(several random subsets and one evenly spread subset each), and report the RMSE of |g| on the poses "
        "each fit did not use (paper Fig. 8). Made for procedures/positions-study.yaml (1296 orientations).",
        "rig analyze positions campaign.h5 --figure positions.png", calibration=False, figure=True)
    positions.add_argument("--sizes", help="comma-separated subset sizes (default: the paper's 1296,648,…,12)")
    positions.add_argument("--subsets", type=_number(1, 1000, integer=True), default=10, help="random subsets per size (default 10)")
    positions.add_argument("--seed", type=_SEED, default=0, help="seed of the random subsets (default 0)")
    positions.add_argument("--mode", choices=["reference", "norm-only"], help="default: the campaign's fit mode")
    _analysis_command(
        analyses, "tilt", "pitch and roll before and after a calibration, against the reference",
        "For every pose of one setpoint and every DUT: the reference pitch and roll (paper Eq. 10) from the "
        "orientation the turntable set, those measured raw and after compensation with the calibration, and "
        "the SEOQ (|before − after| relative to 30°), as in the paper's Table 5. Made for "
        "procedures/tilt-check.yaml.",
        "rig analyze tilt tilt.h5 --calibration campaign.calibration.yaml", calibration=True, figure=False)
    _analysis_command(
        analyses, "cooldown", "temperature coefficient per axis during a free cool-down",
        "For every DUT of a cool-down campaign (procedures/cooldown-60c.yaml): the slope of each axis's output "
        "against the DUT's own temperature, in µg/K, before and after compensation with the calibration "
        "(paper: 1346 → 37 µg/K), and the output's span; the figure shows the outputs over the cool-down "
        "(paper Fig. 11).",
        "rig analyze cooldown cooldown.h5 --calibration campaign.calibration.yaml --figure cool.png",
        calibration=True, figure=True)

    _registry_commands(commands)
    completion = _command(commands, "completion", "print a shell completion script",
                          "Print a completion script for bash (commands, their actions and options; file names "
                          "elsewhere). Load it now with eval \"$(rig completion bash)\", or for good: "
                          "rig completion bash > ~/.local/share/bash-completion/completions/rig",
                          "rig completion bash > ~/.local/share/bash-completion/completions/rig")
    completion.add_argument("shell", choices=["bash"])

    serve = _command(commands, "serve", "a local web dashboard of campaigns and the registry",
                     "Serve the dashboard: running and recent campaigns of the watched folders (state, phase, "
                     "setpoint, temperatures, poses, time left, warnings, refreshed live), each campaign's "
                     "temperature plot, report and certificates, and the registry (a serial's history and "
                     "trend, a part's lot). Campaign files are only read, as rig status reads them. It listens "
                     "on 127.0.0.1; another address needs --token (and TLS is advised: --tls-cert, --tls-key). "
                     "Needs: pip install 'accelcal-rig[dashboard]'.",
                     "rig serve --campaigns campaigns/ --port 8040")
    serve.add_argument("--campaigns", type=Path, action="append", metavar="DIR",
                       help="a folder of campaign files to show (repeatable; default: the current folder)")
    registry_option(serve)
    serve.add_argument("--config", type=Path, metavar="RIG", help="rig config whose registry: to use")
    serve.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    serve.add_argument("--port", type=_number(0, 65535, integer=True), default=8040,
                       help="port (default 8040; 0: any free one, printed)")
    serve.add_argument("--token", help="a secret every request must carry (needed off 127.0.0.1; default "
                                       "$ACCELCAL_DASHBOARD_TOKEN)")
    serve.add_argument("--tls-cert", type=Path, help="TLS certificate (PEM), with --tls-key: serve HTTPS")
    serve.add_argument("--tls-key", type=Path, help="its private key (PEM)")

    report = _command(commands, "report", "write an HTML report with figures of a campaign",
                      "Write REPORT/index.html and REPORT/figures/*.png: the campaign's summary, |g| per pose "
                      "before and after calibration, the raw ellipsoid and calibrated sphere, every parameter "
                      "over temperature with its polynomial, offset drift before and after compensation, RMSE "
                      "per setpoint, the soak traces and the event log. Opens in a browser with no network. "
                      "Needs matplotlib (pip install 'accelcal-rig[report]'). The fit is redone in memory with "
                      "the campaign's options; the file is only read, so a running or aborted campaign works.",
                      "rig report campaign.h5 -o report/")
    report.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    report.add_argument("-o", "--output", type=Path, required=True, help="folder to write (created if needed)")

    certificate = _command(commands, "certificate", "write a calibration certificate per DUT (HTML and PDF)",
                           "Write OUT/<serial>.html and OUT/<serial>.pdf for every DUT of the calibration: the item "
                           "and its identity, the campaign and its instruments, the results, the verification, the "
                           "uncertainty budget, the verdict and fields for signatures. PDFs need WeasyPrint (pip "
                           "install 'accelcal-rig[certificate]'). `rig run` writes them at its end too.",
                           "rig certificate campaign.h5 -o certs/ --operator 'A. Smith'")
    certificate.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    certificate.add_argument("-o", "--output", type=Path, required=True, help="folder to write (created if needed)")
    certificate.add_argument("--calibration", type=Path,
                             help="its calibration file (default: beside the campaign, .calibration.yaml)")
    _certificate_options(certificate)

    export = _command(commands, "export", "write a calibration file as JSON, CSV, a C header or flight-stack parameters",
                      "Write the coefficients of a calibration file for other tools (json: the same structure; "
                      "csv: one row per sensor and parameter) or for firmware (c-header: every sensor's "
                      "polynomials and C99 functions that apply them, accelcal_apply and accelcal_apply_codes), "
                      "or one sensor's bias as a flight stack's thermal compensation (px4-params: TC_A<n>_ for "
                      "QGroundControl; ardupilot-params: INS_TCAL<n>_). Those hold offsets only: what they cannot "
                      "hold is stated on standard error and in the file.",
                      "rig export campaign.calibration.yaml --format c-header -o accel_calibration.h")
    export.add_argument("calibration", type=Path, help="calibration file (YAML, from rig run or rig fit)")
    export.add_argument("--format", required=True, choices=["json", "csv", "c-header", "px4-params", "ardupilot-params"],
                        help="what to write (px4-params, ardupilot-params: one sensor's thermal offsets)")
    export.add_argument("--serial", help="px4-params, ardupilot-params: the sensor (needed when the file has several)")
    export.add_argument("--instance", type=_number(0, 3, integer=True),
                        help="px4-params: n of TC_A<n>_ (0-3, default 0); ardupilot-params: the IMU, n of INS_TCAL<n>_ "
                             "(1-3, default 1)")
    export.add_argument("--device-id", type=_number(1, 2**31 - 1, integer=True),
                        help="px4-params: TC_A<n>_ID, the device id of the accelerometer (its CAL_ACC<k>_ID; "
                             "default 0, which PX4 matches to none)")
    export.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    return parser


def bash_completion(parser: argparse.ArgumentParser) -> str:
    """A bash completion script generated from the parser itself, so it never falls behind the commands."""
    words: dict[str, list[str]] = {"": []}

    def walk(command: argparse.ArgumentParser, key: str) -> None:
        options = [o for action in command._actions for o in action.option_strings]
        children: list[str] = []
        for action in command._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    children.append(name)
                    walk(sub, f"{key} {name}".strip())
        words[key] = children + options

    walk(parser, "")
    cases = "\n".join(f'        "{key}") words="{" ".join(sorted(set(value)))}" ;;' for key, value in sorted(words.items()))
    return f"""# bash completion for rig (accelcal-rig), made by `rig completion bash`
_rig() {{
    local current="${{COMP_WORDS[COMP_CWORD]}}" path="" word words
    for word in "${{COMP_WORDS[@]:1:COMP_CWORD-1}}"; do
        case "$word" in -*) continue ;; esac
        if _rig_words "${{path:+$path }}$word" >/dev/null; then path="${{path:+$path }}$word"; fi
    done
    words=$(_rig_words "$path")
    if [[ "$current" == -* || -n "$words" ]]; then
        COMPREPLY=($(compgen -W "$words" -- "$current"))
    fi
    [[ ${{#COMPREPLY[@]}} -eq 0 ]] && COMPREPLY=($(compgen -f -- "$current"))
    return 0
}}
_rig_words() {{
    local words=""
    case "$1" in
{cases}
        *) return 1 ;;
    esac
    echo "$words"
}}
complete -o filenames -F _rig rig
"""
