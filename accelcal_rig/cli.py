"""`rig`: the command line. Every failure a user can cause is one line on stderr and a non-zero exit."""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from accelcal_rig import __version__
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, stop_when_safe
from accelcal_rig.errors import CampaignAborted, ConfigError, RigError

if TYPE_CHECKING:
    from accelcal_rig.engine.progress import ProgressListener
    from accelcal_rig.engine.session import PreparedCampaign, RunResult

EXIT_INTERRUPTED = 130
#: A failure the program did not foresee (a bug): one line, and this code.
EXIT_INTERNAL = 70
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


def _build_parser() -> argparse.ArgumentParser:
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
    run.add_argument("--overwrite", action="store_true", help="replace an existing campaign file")
    run.add_argument("--resume", action="store_true",
                     help="continue the campaign in the output file if it exists (after a crash, a fault or "
                          "Ctrl-C), else start it")
    run.add_argument("--calibration", type=Path,
                     help="calibration file the final fit writes (default: beside the campaign, .calibration.yaml)")
    run.add_argument("-v", "--verbose", action="store_true", help="log every transition and pose")
    run.add_argument("-q", "--quiet", action="store_true", help="print only warnings and the summary")

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
    resume.add_argument("--calibration", type=Path,
                        help="calibration file the final fit writes (default: beside the campaign, .calibration.yaml)")
    resume.add_argument("-v", "--verbose", action="store_true", help="log every transition and pose")
    resume.add_argument("-q", "--quiet", action="store_true", help="print only warnings and the summary")

    status = _command(commands, "status", "show a campaign file's state and progress",
                      "Show a campaign's state and progress (works on finished, aborted and running files).",
                      "rig status campaign.h5 --json")
    status.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    status.add_argument("--json", action="store_true", help="print one JSON object")

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
    check.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)

    sim = _command(commands, "sim", "serve the simulated rig as real endpoints until interrupted",
                   "Start the simulated rig of a rig config: the chamber on Modbus TCP (127.0.0.1), the "
                   "turntable and each sensor bridge on a pseudo-terminal, in real time. The first line on "
                   "stdout is one JSON object with the endpoints. Ctrl-C stops it.",
                   "rig sim configs/sim.yaml")
    sim.add_argument("rig", type=Path, help="rig config YAML")
    sim.add_argument("--seed", type=_SEED, default=0, help="seed of the simulated noise (default 0)")
    sim.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)

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
                           help="CSV column names, in this order (default: time,x,y,z)")
    recording.add_argument("--time-unit", choices=["s", "ms", "samples"], default="s", help="of the time column")
    recording.add_argument("--rate-hz", type=_number(1e-3, 1e7, "Hz"), help="sample rate, when the time column counts "
                                                                              "samples")
    recording.add_argument("--units", choices=["g", "counts", "m/s2"], default="g", help="of x, y, z (default g)")
    recording.add_argument("--counts-per-g", type=_number(1e-6, 1e12), help="with --units counts (ADXL355 at ±2 g: "
                                                                          "256000)")
    recording.add_argument("--zero-code", type=_number(-1e12, 1e12), default=0.0,
                           help="code of 0 g: 0 for signed codes (default), 32768 for a 16-bit offset-binary ADC")
    recording.add_argument("--serial", help="sensor name in the calibration (default: the file's name; campaign "
                                            "files: the first DUT)")
    recording.add_argument("--setpoint", type=_TEMPERATURE, help="campaign files: the setpoint whose poses to use")
    recording.add_argument("--parameters", choices=["all", "bias-scale"], default="all",
                           help="all: bias, scale, non-orthogonality (9); bias-scale: 6 (default all)")
    recording.add_argument("--temperature-c", type=_TEMPERATURE, help="the recording's temperature, if it has none")
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

    export = _command(commands, "export", "write a calibration file as JSON, CSV or a C header for firmware",
                      "Write the coefficients of a calibration file for other tools (json: the same structure; "
                      "csv: one row per sensor and parameter) or for firmware (c-header: every sensor's "
                      "polynomials and C99 functions that apply them, accelcal_apply and accelcal_apply_codes).",
                      "rig export campaign.calibration.yaml --format c-header -o accel_calibration.h")
    export.add_argument("calibration", type=Path, help="calibration file (YAML, from rig run or rig fit)")
    export.add_argument("--format", required=True, choices=["json", "csv", "c-header"], help="what to write")
    export.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    return parser


@contextmanager
def _campaign_logging(output: Path, verbose: bool, quiet: bool, append: bool,
                      real_clock: bool) -> Iterator[ProgressListener]:
    """Console on stderr at the chosen level (a live status line on a terminal, timestamped lines
    otherwise), the full debug log with progress lines in a file beside the campaign file (appended to by
    a resumed run); yields the progress listener. Everything is detached and closed when the run ends."""
    from accelcal_rig.report.live import LogFileHandler, ProgressLines, StatusLine, TerminalHandler, listeners
    from accelcal_rig.store.paths import log_path

    status = StatusLine(sys.stderr, real_clock) if sys.stderr.isatty() and not quiet else None
    console: logging.Handler
    if status is not None:
        console = TerminalHandler(status)
        console.setFormatter(logging.Formatter("%(message)s"))
    else:
        console = logging.StreamHandler(sys.stderr)
        console.setFormatter(logging.Formatter("%(asctime)s %(levelname)-7s %(message)s", "%Y-%m-%d %H:%M:%S"))
    console.setLevel(logging.DEBUG if verbose else logging.WARNING if quiet else logging.INFO)
    try:
        log_file = LogFileHandler(str(log_path(output)), mode="a" if append else "w")
    except OSError as exc:
        raise ConfigError(f"{log_path(output)}: cannot write the campaign's log: {exc.strerror}") from None
    log_file.setFormatter(logging.Formatter("%(asctime)s %(levelname)-7s %(message)s"))
    LOGGER.setLevel(logging.DEBUG)
    propagate, LOGGER.propagate = LOGGER.propagate, False
    for handler in (console, log_file):
        LOGGER.addHandler(handler)
    lines = ProgressLines(real_clock)
    try:
        yield listeners(lines, status) if status is not None else lines
    finally:
        if status is not None:
            status.close()
        for handler in (console, log_file):
            LOGGER.removeHandler(handler)
            handler.close()
        LOGGER.propagate = propagate


class _StopOnFirstSignal:
    """SIGINT or SIGTERM stops the campaign through its safe state; later signals must not cut that short."""

    def __init__(self) -> None:
        self.stopping = False

    def __call__(self, signum: int, frame: object) -> None:
        if self.stopping:
            LOGGER.warning("%s ignored: already stopping, the rig is being made safe", signal.Signals(signum).name)
            return
        self.stopping = True
        stop_when_safe(KeyboardInterrupt() if signum == signal.SIGINT else TerminationRequested())


def _cmd_run(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.session import prepare
    from accelcal_rig.store.paths import journal_path

    if args.output.is_dir():
        raise ConfigError(f"{args.output}: is a folder; name the campaign file to write")
    prepared = prepare(args.procedure, args.config, args.faults)
    exists = args.output.exists() or journal_path(args.output).exists()
    if exists and not (args.overwrite or args.resume):
        raise ConfigError(f"{args.output}: campaign file exists; continue it with --resume, or choose another -o "
                          "or pass --overwrite")
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    return _execute(prepared, args.output, args, dry_run=args.dry_run, seed=args.seed, overwrite=args.overwrite,
                    resume=args.resume and exists)


def _cmd_plan(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.estimate import estimate_duration
    from accelcal_rig.engine.session import prepare
    from accelcal_rig.report.plan_summary import plan_json, plan_lines

    prepared = prepare(args.procedure, args.config)
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    if args.json:
        print(json.dumps(plan_json(prepared, estimate)))
    else:
        print("\n".join(plan_lines(prepared, estimate)))
    return 0


def _cmd_resume(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.session import prepare
    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(args.campaign)
    procedure = args.procedure or Path(str(stored.attrs.get("procedure_path", "")))
    if not procedure.is_file():
        raise ConfigError(f"{args.campaign}: its procedure {procedure} is gone; pass --procedure with the same "
                          "procedure")
    prepared = prepare(procedure, args.config, args.faults)
    return _execute(prepared, args.campaign, args, dry_run=bool(stored.attrs.get("dry_run", False)),
                    seed=int(stored.attrs.get("seed", 0)), overwrite=False, resume=True)


def _check_free_space(prepared: PreparedCampaign, output: Path, dry_run: bool, overwrite: bool) -> None:
    """Refuse to start a campaign the disk cannot hold (with a margin), before anything is touched."""
    from accelcal_rig.durable import free_bytes
    from accelcal_rig.store.paths import journal_path
    from accelcal_rig.store.space import START_MARGIN, megabytes

    estimate = prepared.storage(dry_run)
    replaced = sum(p.stat().st_size for p in (output, journal_path(output)) if overwrite and p.is_file())
    free = free_bytes(output.parent) + replaced
    needed = int(START_MARGIN * estimate.need_bytes)
    if free < needed:
        raise ConfigError(f"{output}: {megabytes(free)} free on {output.parent.resolve()}, the campaign needs about "
                          f"{megabytes(needed)} ({START_MARGIN:g} × its estimated {megabytes(estimate.need_bytes)}): "
                          "free some space or choose another -o")


def _execute(prepared: PreparedCampaign, output: Path, args: argparse.Namespace, *, dry_run: bool, seed: int,
             overwrite: bool, resume: bool) -> int:
    """Run or resume under the CLI's signal handling and logging; print the summary. The campaign is
    locked before anything of it changes, the log included."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.session import NothingToResume
    from accelcal_rig.store.lock import campaign_lock

    calibration = args.calibration or output.with_suffix(".calibration.yaml")
    if not calibration.parent.is_dir():
        raise ConfigError(f"{calibration}: folder {calibration.parent} does not exist")
    stop = _StopOnFirstSignal()
    previous = {signum: signal.signal(signum, stop) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        with campaign_lock(output, "rig resume" if resume else "rig run"):
            if not resume:
                _check_free_space(prepared, output, dry_run, overwrite)
            with _campaign_logging(output, args.verbose, args.quiet, append=resume, real_clock=not dry_run) as progress:
                result = run_campaign(prepared, output, dry_run=dry_run, seed=seed, overwrite=overwrite,
                                      calibration=calibration, resume=resume, progress=progress)
    except NothingToResume as done:
        print(done)
        return 0
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    try:
        return _print_summary(prepared, result, dry_run)
    except (KeyboardInterrupt, TerminationRequested):
        print(f"rig: interrupted after the campaign ended ({result.summary.state}); {result.output} holds all of it",
              file=sys.stderr)
        return EXIT_INTERRUPTED


def _print_summary(prepared: PreparedCampaign, result: RunResult, dry_run: bool) -> int:
    summary = result.summary
    setpoints = summary.setpoints_c
    size_mb = result.output.stat().st_size / 1e6 if result.output.is_file() else 0.0
    print(f"campaign {summary.state}: {prepared.procedure.model.name}")
    print(f"  setpoints  {len(setpoints)} ({min(setpoints):g} … {max(setpoints):g} °C)")
    print(f"  poses      {summary.poses_done} of {summary.poses_total} × {summary.n_duts} DUTs × "
          f"{prepared.procedure.model.acquisition.samples_per_pose} samples")
    print(f"  duration   {format_duration(summary.virtual_duration_s)} {'virtual' if dry_run else 'clock'}, "
          f"{result.wall_s:.1f} s wall")
    print(f"  output     {result.output} ({size_mb:.1f} MB)")
    if summary.fit_failed:
        print(f"rig: campaign done but the fit failed: {_one_line(Exception(summary.fit))}", file=sys.stderr)
        return 1
    print(f"  fit        {summary.fit or 'none (the procedure measures only: fit.mode none)'}")
    if result.problems:
        print(f"rig: error: campaign done, but {result.problems[0]}", file=sys.stderr)
        return 1
    return 0


def _cmd_status(args: argparse.Namespace) -> int:
    from accelcal_rig.store.read import campaign_status

    status = campaign_status(args.campaign)
    if args.json:
        print(json.dumps(status))
        return 0
    for key, value in status.items():
        print(f"{key:17s}{value}")
    return 0


def _cmd_repair(args: argparse.Namespace) -> int:
    from accelcal_rig.store.repair import repair_campaign

    for line in repair_campaign(args.campaign):
        print(f"{args.campaign}: {line}")
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from accelcal_rig.assembly import connected
    from accelcal_rig.config.load import load_rig, with_faults
    from accelcal_rig.engine.check import check_lines

    rig = with_faults(load_rig(args.rig), args.faults)
    with connected(rig, dry_run=args.dry_run) as instruments:
        for line in check_lines(instruments):
            print(line, flush=True)
    print(f"rig {rig.model.name}: every instrument answered as configured")
    return 0


def _cmd_sim(args: argparse.Namespace) -> int:
    import threading

    from accelcal_rig.assembly import served_rig
    from accelcal_rig.config.load import load_rig, with_faults
    from accelcal_rig.core.clock import RealClock

    rig = with_faults(load_rig(args.rig), args.faults)
    stop = threading.Event()
    previous = {signum: signal.signal(signum, lambda *_: stop.set()) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        with served_rig(rig.model, RealClock(), args.seed) as simulated:
            print(json.dumps(simulated.describe()), flush=True)
            while not stop.wait(0.5):
                pass
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    print("rig sim: stopped", file=sys.stderr)
    return 0


def _cmd_fit(args: argparse.Namespace) -> int:
    import numpy as np

    from accelcal_rig.fit.campaign_fit import fit_and_save, summary_line
    from accelcal_rig.fit.recorded_options import recorded_options
    from accelcal_rig.store.lock import holder
    from accelcal_rig.store.read import usable_campaign

    running = holder(args.campaign)
    if running is not None:
        raise ConfigError(f"{args.campaign}: a campaign is running on it, {running}: fit it once it is done")
    campaign = usable_campaign(args.campaign)
    for note in campaign.notes:
        print(f"rig: warning: {args.campaign}: {note}", file=sys.stderr)
    options = recorded_options(campaign.attrs, str(args.campaign), mode=args.mode, degree=args.degree,
                               free=args.parameters, out_of_range=args.out_of_range,
                               temperature_model=args.temperature_model)
    if options is None:
        raise ConfigError(f"{args.campaign}: its procedure asked for no fit (fit.mode: none); choose one with "
                          "--mode reference or --mode norm-only")
    if args.output.is_dir():
        raise ConfigError(f"{args.output}: is a folder; name the calibration file to write")
    try:
        _, report = fit_and_save(campaign, args.campaign, args.output, options)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise RigError(f"{args.campaign}: fit failed: {str(exc).splitlines()[0]}") from None
    if campaign.state != "done":
        print(f"rig: warning: campaign state is {campaign.state}: fitted the poses stored so far", file=sys.stderr)
    if args.json:
        print(json.dumps(report))
    else:
        _print_fit_table(report)
        print(summary_line(report, args.output))
    return 0


def _cmd_fit_recording(args: argparse.Namespace) -> int:
    from accelcal_rig.fit.calibration import save_calibration
    from accelcal_rig.handheld.calibrate import fit_recording
    from accelcal_rig.handheld.recording import CsvLayout, read_campaign_recording, read_csv_recording
    from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals

    if not args.recording.exists():
        raise ConfigError(f"{args.recording}: no such file")
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    if args.output.is_dir():
        raise ConfigError(f"{args.output}: is a folder; name the calibration file to write")
    settings = DetectorSettings(args.window_s, args.init_s, args.threshold_factor, args.min_interval_s)
    if args.recording.suffix in (".h5", ".hdf5"):
        recording = read_campaign_recording(args.recording, args.serial, args.setpoint)
        serial = recording.serial or args.recording.stem
    else:
        layout = CsvLayout.parse_columns(args.columns, time_unit=args.time_unit, rate_hz=args.rate_hz,
                                         units=args.units, counts_per_g=args.counts_per_g, zero_code=args.zero_code)
        recording = read_csv_recording(args.recording, layout)
        serial = args.serial or args.recording.stem
    detection = detect_static_intervals(recording.t_s, recording.accel_g, recording.temperature_c, settings,
                                        recording.source)
    result = fit_recording(recording, detection, args.parameters, serial, args.temperature_c)
    save_calibration(result.calibration, args.output)
    if args.json:
        print(json.dumps(result.report))
        return 0
    report = result.report
    print(f"{len(report['intervals'])} static intervals in {recording.source} ({report['samples']} samples at "
          f"{report['rate_hz']:.4g} Hz; threshold {report['threshold_g2']:.3g} g², {args.threshold_factor:g} × the "
          f"first {args.init_s:g} s)")
    print(f"{'#':>3s} {'start s':>9s} {'end s':>9s} {'samples':>8s} {'mean x, y, z (g)':>29s} {'|g|−1 before':>13s} "
          f"{'after (mg)':>11s}")
    for k, interval in enumerate(report["intervals"], start=1):
        mean = " ".join(f"{v:+9.5f}" for v in interval["mean_g"])
        print(f"{k:3d} {interval['start_s']:9.2f} {interval['end_s']:9.2f} {interval['samples']:8d} {mean:>29s} "
              f"{interval['norm_before_mg']:13.3f} {interval['norm_after_mg']:11.4f}")
    for warning in report["warnings"]:
        print(f"warning: {warning}")
    print(f"calibration → {args.output}: norm-only, {args.parameters} parameters, |g| RMSE "
          f"{report['rmse_before_mg']:.3f} → {report['rmse_after_mg']:.4f} mg (noise floor "
          f"{report['noise_floor_mg']:.4f} mg) at {report['temperature_c']:.1f} °C")
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    return {"positions": _analyze_positions, "tilt": _analyze_tilt, "cooldown": _analyze_cooldown}[args.analysis](args)


def _calibrations_for(calibration_path: Path, campaign: Path, serials: list[str]):  # noqa: ANN202
    from accelcal_rig.fit.calibration import load_calibration

    calibration = load_calibration(calibration_path)
    missing = [serial for serial in serials if serial not in calibration.sensors]
    if missing:
        raise ConfigError(f"{calibration_path}: no calibration for {', '.join(missing)} of {campaign} "
                          f"(it has {', '.join(calibration.sensors)})")
    return calibration


def _analyze_cooldown(args: argparse.Namespace) -> int:
    import dataclasses

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.cooldown import analyse_cooldown
    from accelcal_rig.fit.calibration import plain

    if args.figure is not None:
        _check_figure_path(args.figure)
    _, duts, _ = poses_at_setpoint(args.campaign, args.setpoint)
    calibration = _calibrations_for(args.calibration, args.campaign, list(duts))
    results = [analyse_cooldown(poses, calibration.sensors[serial]) for serial, poses in duts.items()]
    if args.figure is not None:
        from accelcal_rig.report.analysis_figures import cooldown_figure

        cooldown_figure(results, args.figure)
    if args.json:
        print(json.dumps(plain({"calibration": str(args.calibration), "sensors": [
            {k: v for k, v in dataclasses.asdict(r).items() if k not in ("t_s", "before_g", "after_g")}
            | {"records": len(r.t_s)} for r in results]})))
        return 0
    print(f"{args.campaign}: free cool-down, temperature coefficient per axis (µg/K) with {args.calibration}")
    print(f"{'sensor':14s} {'records':>7s} {'from … to (°C)':>16s} {'before x, y, z':>26s} {'after x, y, z':>26s}")
    for r in results:
        before = " ".join(f"{v:+8.1f}" for v in r.coefficient_before_ug_per_k)
        after = " ".join(f"{v:+8.2f}" for v in r.coefficient_after_ug_per_k)
        print(f"{r.serial:14s} {len(r.t_s):7d} {r.temperature_c.max():7.1f} … {r.temperature_c.min():5.1f} "
              f"{before:>26s} {after:>26s}")
        if r.outside_range:
            print(f"  warning: {r.outside_range} records outside the calibrated range: clamped or extrapolated as "
                  "the calibration file says")
    if args.figure is not None:
        print(f"figure → {args.figure}")
    return 0


def _analyze_tilt(args: argparse.Namespace) -> int:
    import dataclasses

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.tilt import tilt_rows, worst_errors_deg
    from accelcal_rig.fit.calibration import plain

    setpoint, duts, numbers = poses_at_setpoint(args.campaign, args.setpoint)
    calibration = _calibrations_for(args.calibration, args.campaign, list(duts))
    rows = {serial: tilt_rows(poses, numbers, calibration.sensors[serial]) for serial, poses in duts.items()}
    outside = [f"{s} ({duts[s].temperature_c.min():.1f}…{duts[s].temperature_c.max():.1f} °C outside "
               f"{calibration.sensors[s].validity_c[0]:.1f}…{calibration.sensors[s].validity_c[1]:.1f} °C)"
               for s in duts if not (calibration.sensors[s].validity_c[0] <= duts[s].temperature_c.min()
                                     and duts[s].temperature_c.max() <= calibration.sensors[s].validity_c[1])]
    if args.json:
        print(json.dumps(plain({"setpoint_c": setpoint, "calibration": str(args.calibration), "outside_range": outside,
                                "rows": [dataclasses.asdict(r) for sensor in rows.values() for r in sensor]})))
        return 0
    print(f"{args.campaign} at {setpoint:g} °C with {args.calibration}: pitch; roll (degrees), paper Eq. 10")
    print(f"{'sensor':14s} {'pose':>4s} {'reference':>16s} {'without calibration':>20s} {'after calibration':>20s} "
          f"{'SEOQ (%)':>12s}")
    for serial, sensor_rows in rows.items():
        for r in sensor_rows:
            pair = lambda v, d: f"{v[0]:.{d}f}; {v[1]:.{d}f}"  # noqa: E731
            print(f"{serial:14s} {r.pose_number:4d} {pair(r.reference_deg, 2):>16s} {pair(r.before_deg, 3):>20s} "
                  f"{pair(r.after_deg, 3):>20s} {pair(r.seoq_percent, 2):>12s}")
        before, after = worst_errors_deg(sensor_rows)
        print(f"{serial:14s} worst |error|: {before:.3f}° without, {after:.4f}° after calibration")
    for note in outside:
        print(f"warning: {note}: the calibration was clamped to its range")
    return 0


def _analyze_positions(args: argparse.Namespace) -> int:
    import dataclasses

    import numpy as np

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.positions import PAPER_SIZES, floor_mg, score_subsets, summarise
    from accelcal_rig.fit.calibration import plain
    from accelcal_rig.fit.recorded_options import NO_FIT, recorded_options, requested_mode
    from accelcal_rig.store.read import load_campaign

    try:
        sizes = tuple(int(v) for v in args.sizes.split(",")) if args.sizes else PAPER_SIZES
    except ValueError:
        raise ConfigError(f"--sizes: {args.sizes!r}: expected whole numbers separated by commas") from None
    if min(sizes) < 6 or args.subsets < 1:
        raise ConfigError("--sizes: at least 6 positions per subset; --subsets: at least 1")
    if args.figure is not None:
        _check_figure_path(args.figure)
    setpoint, duts, _ = poses_at_setpoint(args.campaign, args.setpoint)
    attrs = load_campaign(args.campaign).attrs
    recorded = requested_mode(attrs)
    mode = args.mode or ("reference" if recorded == NO_FIT else recorded)  # measure-only: the table's reference
    options = recorded_options(attrs, str(args.campaign), mode=mode)
    assert options is not None
    free = options.free
    rows, floors = [], {}
    for serial, poses in duts.items():
        scores = score_subsets(poses, sizes, mode, free, args.subsets, np.random.default_rng(args.seed))  # type: ignore[arg-type]
        rows += summarise(serial, scores)
        floors[serial] = floor_mg(poses)
    if args.figure is not None:
        from accelcal_rig.report.analysis_figures import positions_figure

        positions_figure(rows, floors, mode, args.figure)
    if args.json:
        print(json.dumps(plain({"setpoint_c": setpoint, "mode": mode, "noise_floor_mg": floors,
                                "sizes": [dataclasses.asdict(r) for r in rows]})))
        return 0
    print(f"{args.campaign}: {mode} fits at {setpoint:g} °C, RMSE of |g| on the poses each fit left out (mg); "
          f"{args.subsets} random subsets per size")
    print(f"{'sensor':14s} {'positions':>9s} {'before':>8s} {'evenly spread':>14s} {'random median':>14s} "
          f"{'random worst':>13s} {'failed':>7s}")
    for r in rows:
        print(f"{r.serial:14s} {r.size:9d} {r.before_mg:8.3f} {r.structured_mg:14.4f} {r.random_median_mg:14.4f} "
              f"{r.random_max_mg:13.4f} {r.failed:7d}")
    print("noise floor (mg): " + ", ".join(f"{k} {v:.4f}" for k, v in floors.items())
          + "; the full set is scored on its own poses")
    if args.figure is not None:
        print(f"figure → {args.figure}")
    return 0


def _check_figure_path(path: Path) -> None:
    from accelcal_rig.report.figures import pyplot

    pyplot()  # a missing extra is a one-line error before any work
    if not path.parent.is_dir():
        raise ConfigError(f"{path}: folder {path.parent} does not exist")


def _cmd_report(args: argparse.Namespace) -> int:
    from accelcal_rig.report.figures import pyplot
    from accelcal_rig.report.html_report import write_report

    pyplot()  # before reading anything: a missing extra is a one-line error
    if args.output.exists() and not args.output.is_dir():
        raise ConfigError(f"{args.output}: exists and is not a folder")
    page = write_report(args.campaign, args.output)
    print(f"report → {page}")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from accelcal_rig.durable import write_text_atomically
    from accelcal_rig.export.c_header import to_c_header
    from accelcal_rig.export.tables import to_csv, to_json
    from accelcal_rig.fit.calibration import load_calibration

    calibration = load_calibration(args.calibration)
    text = {"json": to_json, "csv": to_csv, "c-header": to_c_header}[args.format](calibration)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    write_text_atomically(args.output, text, f"the {args.format} export")
    print(f"{args.format} of {len(calibration.sensors)} sensors → {args.output}")
    return 0


def _print_fit_table(report: dict) -> None:
    print(f"{'sensor':14s} {'before mg':>10s} {'after mg':>9s} {'floor mg':>9s} {'drift before mg':>22s} "
          f"{'drift after mg':>22s}")
    for serial, r in report.items():
        drift_before = " ".join(f"{v:6.2f}" for v in r["drift_before_mg"])
        drift_after = " ".join(f"{v:6.3f}" for v in r["drift_after_mg"])
        print(f"{serial:14s} {r['rmse_before_mg']:10.3f} {r['rmse_after_mg']:9.4f} {r['noise_floor_mg']:9.4f} "
              f"{drift_before:>22s} {drift_after:>22s}")
        for warning in r["warnings"]:
            print(f"  warning: {warning}")


def run_program() -> None:
    """The `rig` executable: run the command, then exit without letting a late signal crash the exit.

    By the time a command returns, its campaign is recorded (done, or aborted and safe); a second
    Ctrl-C arriving while the interpreter shuts down must not turn that into a kill by signal.
    """
    try:
        code = main()
    except KeyboardInterrupt:  # a signal between start and the command's own handling
        print("rig: interrupted before the campaign started; nothing was moved", file=sys.stderr)
        code = EXIT_INTERRUPTED
    except BrokenPipeError:  # `rig status … | head`: the reader has gone; so has the need to print
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 0
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise SystemExit(code)


def _one_line(error: BaseException) -> str:
    """An error's message as one line, whatever text from a file it quotes."""
    return " ".join(str(error).splitlines())


def main(argv: list[str] | None = None) -> int:
    args = _build_parser().parse_args(argv)
    # Driver libraries log their own view of a failure; ours is the one line that names the instrument.
    logging.getLogger("pymodbus").addHandler(logging.NullHandler())
    logging.getLogger("pymodbus").propagate = False
    handler = {"run": _cmd_run, "plan": _cmd_plan, "resume": _cmd_resume, "status": _cmd_status, "repair": _cmd_repair,
               "fit": _cmd_fit, "check": _cmd_check,
               "sim": _cmd_sim, "report": _cmd_report, "export": _cmd_export,
               "fit-recording": _cmd_fit_recording, "analyze": _cmd_analyze}[args.command]
    try:
        return handler(args)
    except CampaignAborted as exc:
        print(f"rig: campaign aborted, rig in safe state: {_one_line(exc)}", file=sys.stderr)
        interrupted = isinstance(exc.__cause__, (KeyboardInterrupt, TerminationRequested))
        return EXIT_INTERRUPTED if interrupted else exc.exit_code
    except RigError as exc:
        print(f"rig: error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except (KeyboardInterrupt, TerminationRequested):
        print("rig: interrupted before the campaign started; nothing was moved", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - a bug still reaches the operator as one line, not a traceback
        if os.environ.get("RIG_TRACEBACK") or isinstance(exc, BrokenPipeError):
            raise
        detail = str(exc).strip().splitlines()
        print(f"rig: internal error: {type(exc).__name__}{': ' + detail[0] if detail else ''} (a bug in accelcal-rig; "
              "please report it with the command; RIG_TRACEBACK=1 shows where)", file=sys.stderr)
        return EXIT_INTERNAL
