"""`rig`: the command line. Every failure a user can cause is one line on stderr and a non-zero exit."""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from accelcal_rig.cli_parser import build_parser
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, stop_when_safe
from accelcal_rig.core.units import gravity_statement
from accelcal_rig.errors import CampaignAborted, ConfigError, RigError

if TYPE_CHECKING:
    from accelcal_rig.engine.preparation import PreparedCampaign
    from accelcal_rig.engine.progress import ProgressListener
    from accelcal_rig.engine.session import NothingToResume, RunResult
    from accelcal_rig.fit.calibration import CalibrationFile

EXIT_INTERRUPTED = 130
#: A failure the program did not foresee (a bug): one line, and this code.
EXIT_INTERNAL = 70
#: `--fail-on-reject`: the campaign and the fit went through, and at least one DUT failed its limits.
EXIT_REJECTED = 3
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
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.store.paths import journal_path

    if args.output.is_dir():
        raise ConfigError(f"{args.output}: is a folder; name the campaign file to write")
    if args.chamber_profile and not args.dry_run:
        raise ConfigError("--chamber-profile swaps in a simulated chamber: only with --dry-run")
    exists = args.output.exists() or journal_path(args.output).exists()
    profile = args.chamber_profile
    if args.resume and exists and profile is None:  # continue with the chamber the campaign was started with
        from accelcal_rig.store.read import load_campaign

        profile = str(load_campaign(args.output).attrs.get("chamber_profile", "")) or None
    prepared = prepare(args.procedure, args.config, args.faults, profile)
    if exists and not (args.overwrite or args.resume):
        raise ConfigError(f"{args.output}: campaign file exists; continue it with --resume, or choose another -o "
                          "or pass --overwrite")
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    return _execute(prepared, args.output, args, dry_run=args.dry_run, seed=args.seed, overwrite=args.overwrite,
                    resume=args.resume and exists)


def _cmd_plan(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.estimate import estimate_duration
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.report.plan_summary import plan_json, plan_lines

    prepared = prepare(args.procedure, args.config)
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    if args.json:
        print(json.dumps(plan_json(prepared, estimate)))
    else:
        print("\n".join(plan_lines(prepared, estimate)))
    return 0


def _cmd_resume(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(args.campaign)
    procedure = args.procedure or Path(str(stored.attrs.get("procedure_path", "")))
    if not procedure.is_file():
        raise ConfigError(f"{args.campaign}: its procedure {procedure} is gone; pass --procedure with the same "
                          "procedure")
    prepared = prepare(procedure, args.config, args.faults, str(stored.attrs.get("chamber_profile", "")) or None)
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
        return _complete_campaign_verdicts(done, output, calibration, args)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    try:
        code = _print_summary(prepared, result, dry_run, args.fail_on_reject)
        if result.summary.fit and not result.summary.fit_failed:
            code = max(code, _certify_after_run(output, calibration, args))
            _record(args.registry, _rig_registry(prepared.rig.model.registry, prepared.rig.path), output,
                    lambda: _campaign_entries(output, calibration))
        return code
    except (KeyboardInterrupt, TerminationRequested):
        print(f"rig: interrupted after the campaign ended ({result.summary.state}); {result.output} holds all of it",
              file=sys.stderr)
        return EXIT_INTERRUPTED


def _print_summary(prepared: PreparedCampaign, result: RunResult, dry_run: bool, fail_on_reject: bool) -> int:
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
    if summary.fit:
        print(f"  gravity    {gravity_statement(prepared.rig.model.gravity_m_s2)}")
    for warning in summary.fit_warnings:
        print(f"  warning    {warning}")
    for serial, (verdict, reasons) in summary.verdicts.items():
        print(f"  verdict    {serial} {verdict}" + (f": {'; '.join(reasons)}" if verdict == "FAIL" else ""))
    if result.problems:
        print(f"rig: error: campaign done, but {result.problems[0]}", file=sys.stderr)
        return 1
    return _rejected_exit(summary.rejected, fail_on_reject)


def _campaign_entries(campaign: Path, calibration: Path) -> list:
    from accelcal_rig.registry.entries import campaign_entries

    return campaign_entries(campaign, calibration)


def _rig_registry(value: str | None, rig_path: Path) -> str | None:
    from accelcal_rig.registry.location import configured

    return configured(value, rig_path)


def _stored_rig_registry(campaign: Path) -> str | None:
    """The `registry:` of the rig config a campaign was run with (as it stored it)."""
    import yaml

    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(campaign)
    value = (yaml.safe_load(stored.header.rig_yaml) or {}).get("registry")
    return _rig_registry(value, Path(str(stored.attrs.get("rig_path", campaign)))) if value else None


def _record(flag: str | None, configured: str | None, source: Path, entries: Callable[[], list],
            json_output: bool = False, later: str | None = None) -> None:
    """Record a finished fit in the registry; a registry that cannot take it is a warning naming how to
    record it later, never a loss: the calibration file is written already. Beside a JSON report the line
    goes to stderr, so stdout stays one JSON object."""
    from alembic.util.exc import CommandError
    from sqlalchemy.exc import SQLAlchemyError

    from accelcal_rig.cli_registry import register
    from accelcal_rig.registry.location import registry_url

    try:
        print(register(registry_url(flag, configured), entries()), file=sys.stderr if json_output else sys.stdout)
    except (RigError, SQLAlchemyError, OSError, CommandError) as exc:
        print(f"rig: warning: not recorded in the registry: {_one_line(exc)} (record it later: "
              f"{later or f'rig registry add {source}'})", file=sys.stderr)


def _rejected_exit(rejected: list[str], fail_on_reject: bool) -> int:
    if rejected and fail_on_reject:
        print(f"rig: {len(rejected)} DUT(s) failed their acceptance limits: {', '.join(rejected)}", file=sys.stderr)
        return EXIT_REJECTED
    return 0


def _cmd_status(args: argparse.Namespace) -> int:
    from accelcal_rig.fit.campaign_file import calibration_verdicts
    from accelcal_rig.status_text import status_lines, watch_header
    from accelcal_rig.store.read import campaign_status

    def current() -> dict:
        return {**campaign_status(args.campaign), **calibration_verdicts(args.campaign, args.calibration)}

    if args.json and not args.watch:
        print(json.dumps(current()))
        return 0
    if not args.watch:
        print("\n".join(status_lines(current())))
        return 0
    import time

    try:
        while True:
            status = current()
            if args.json:
                print(json.dumps(status), flush=True)
            else:
                clear = "\x1b[H\x1b[2J" if sys.stdout.isatty() else ""
                print(clear + "\n".join(status_lines(status)) + f"\n({watch_header(status, args.watch)})", flush=True)
            if status["state"] not in ("created", "running"):
                return 0
            time.sleep(args.watch)
    except KeyboardInterrupt:
        return 0


def _cmd_repair(args: argparse.Namespace) -> int:
    from accelcal_rig.store.repair import repair_campaign

    for line in repair_campaign(args.campaign):
        print(f"{args.campaign}: {line}")
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from accelcal_rig.assembly import connected
    from accelcal_rig.config.load import load_rig, load_rig_for_check, with_faults
    from accelcal_rig.engine.check import check_lines

    only = frozenset(args.only or ("chamber", "turntable", "sensors"))
    rig = with_faults(load_rig_for_check(args.rig, only) if args.only else load_rig(args.rig), args.faults)
    with connected(rig, dry_run=args.dry_run, only=only) as instruments:
        for line in check_lines(instruments, rig.model):
            print(line, flush=True)
    if args.only:
        print(f"rig {rig.model.name}: the {' and '.join(sorted(only))} answered as configured (only those checked)")
    else:
        print(f"rig {rig.model.name}: every instrument answered as configured")
    return 0


def _cmd_sim(args: argparse.Namespace) -> int:
    import threading

    from accelcal_rig.assembly import served_rig
    from accelcal_rig.config.load import load_rig, with_chamber_profile, with_faults
    from accelcal_rig.core.clock import RealClock

    rig = with_chamber_profile(with_faults(load_rig(args.rig), args.faults), args.chamber_profile)
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
    from accelcal_rig.fit.campaign_file import fit_campaign_file
    from accelcal_rig.fit.campaign_fit import summary_line

    outcome = fit_campaign_file(args.campaign, args.output, mode=args.mode, degree=args.degree, free=args.parameters,
                                out_of_range=args.out_of_range, temperature_model=args.temperature_model)
    for warning in outcome.warnings:
        print(f"rig: warning: {warning}", file=sys.stderr)
    if args.json:
        print(json.dumps(outcome.report))
    else:
        _print_fit_table(outcome.report)
        print(summary_line(outcome.report, args.output))
        print(f"gravity: {gravity_statement(next(iter(outcome.report.values()))['gravity_m_s2'])}")
    _record(args.registry, _stored_rig_registry(args.campaign), args.campaign,
            lambda: _campaign_entries(args.campaign, args.output), args.json)
    rejected = [serial for serial, r in outcome.report.items() if r["verdict"] == "FAIL"]
    return _rejected_exit(rejected, args.fail_on_reject)


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
    gravity = args.gravity_m_s2 if args.gravity_m_s2 is not None else recording.gravity_m_s2
    result = fit_recording(recording, detection, args.parameters, serial, args.temperature_c, gravity)
    save_calibration(result.calibration, args.output)
    record = lambda: _recording_entries(args.recording, result.calibration, args.part)  # noqa: E731
    if args.json:
        print(json.dumps(result.report))
        _record(args.registry, None, args.recording, record, json_output=True,
                later="run this rig fit-recording again once the registry is reachable")
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
    chi2 = "n/a (no degrees of freedom left)" if report["chi2_reduced_before"] is None else (
        f"{report['chi2_reduced_before']:.2f}" + (f" → {report['chi2_reduced']:.2f} with a scatter floor of "
                                                   f"{report['scatter_floor_mg']:.4f} mg" if report["scatter_floor_mg"]
                                                   else ""))
    print(f"calibration → {args.output}: norm-only, {args.parameters} parameters, |g| RMSE "
          f"{report['rmse_before_mg']:.3f} → {report['rmse_after_mg']:.4f} mg (noise floor "
          f"{report['noise_floor_mg']:.4f} mg) at {report['temperature_c']:.1f} °C; χ²_red {chi2}; outputs in "
          f"{report['units']}")
    _record(args.registry, None, args.recording, record,
            later="run this rig fit-recording again once the registry is reachable")
    return 0


def _recording_entries(recording: Path, calibration: CalibrationFile, part: str) -> list:
    from accelcal_rig.registry.entries import recording_entries

    return recording_entries(recording, calibration, part)


def _cmd_completion(args: argparse.Namespace) -> int:
    from accelcal_rig.cli_parser import bash_completion

    sys.stdout.write(bash_completion(build_parser()))
    return 0


def _cmd_serve(args: argparse.Namespace) -> int:
    import ipaddress
    import socket

    from accelcal_rig.registry.location import configured, registry_url

    try:
        import uvicorn

        from accelcal_rig.web.app import create_app
    except ModuleNotFoundError as exc:
        raise ConfigError(f"rig serve needs {exc.name}: pip install 'accelcal-rig[dashboard]'") from None
    token = args.token or os.environ.get("ACCELCAL_DASHBOARD_TOKEN") or None
    try:
        loopback = args.host == "localhost" or ipaddress.ip_address(args.host).is_loopback
    except ValueError:
        loopback = False
    if not loopback and token is None:
        raise ConfigError(f"--host {args.host}: off 127.0.0.1 the dashboard needs --token (anyone on the network "
                          "could read it otherwise)")
    if (args.tls_cert is None) != (args.tls_key is None):
        raise ConfigError("--tls-cert and --tls-key go together")
    if args.tls_cert is not None:
        import ssl

        try:  # before anything is printed: a wrong file is one line naming it
            ssl.create_default_context(ssl.Purpose.CLIENT_AUTH).load_cert_chain(args.tls_cert, args.tls_key)
        except (OSError, ssl.SSLError) as exc:
            raise ConfigError(f"--tls-cert {args.tls_cert} --tls-key {args.tls_key}: cannot load: {exc}") from None
    folders = args.campaigns or [Path.cwd()]
    missing = [folder for folder in folders if not folder.is_dir()]
    if missing:
        raise ConfigError(f"--campaigns {missing[0]}: not a folder")
    from_config = None
    if args.config is not None:
        from accelcal_rig.config.load import load_rig

        rig = load_rig(args.config)
        from_config = configured(rig.model.registry, rig.path)
    from urllib.parse import quote

    from accelcal_rig.web.app import LOOPBACK_HOSTS

    app = create_app(folders, registry_url(args.registry, from_config), token, tls=args.tls_cert is not None,
                     hosts=[*LOOPBACK_HOSTS, args.host])
    # Listening before the address is printed: whoever reads it can connect at once (and port 0 works).
    family = socket.AF_INET6 if ":" in args.host else socket.AF_INET
    listening = socket.socket(family, socket.SOCK_STREAM)
    listening.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        listening.bind((args.host, int(args.port)))
    except OSError as exc:
        raise ConfigError(f"--host {args.host} --port {args.port}: cannot listen there: {exc.strerror}") from None
    listening.listen(128)
    port = listening.getsockname()[1]
    scheme = "https" if args.tls_cert else "http"
    print(f"dashboard on {scheme}://{args.host}:{port}/" + (f"?token={quote(token, safe='')}" if token else ""),
          flush=True)
    config = uvicorn.Config(app, log_level="warning", ssl_certfile=args.tls_cert, ssl_keyfile=args.tls_key)
    uvicorn.Server(config).run(sockets=[listening])
    return 0


def _cmd_registry(args: argparse.Namespace) -> int:
    from accelcal_rig.cli_registry import registry_command

    return registry_command(args)


def _cmd_analyze(args: argparse.Namespace) -> int:
    from accelcal_rig.cli_analyze import analyze

    return analyze(args)


def _cmd_report(args: argparse.Namespace) -> int:
    from accelcal_rig.report.figures import pyplot
    from accelcal_rig.report.html_report import write_report

    pyplot()  # before reading anything: a missing extra is a one-line error
    if args.output.exists() and not args.output.is_dir():
        raise ConfigError(f"{args.output}: exists and is not a folder")
    page = write_report(args.campaign, args.output)
    print(f"report → {page}")
    return 0


def _cmd_certificate(args: argparse.Namespace) -> int:
    calibration = args.calibration or args.campaign.with_suffix(".calibration.yaml")
    if not calibration.is_file():
        raise ConfigError(f"{calibration}: no calibration file: fit the campaign first (rig fit), or name it with "
                          "--calibration")
    if args.output.exists() and not args.output.is_dir():
        raise ConfigError(f"{args.output}: exists and is not a folder")
    _certify(args.campaign, calibration, args.output, args.operator, not args.no_pdf)
    return 0


def _complete_campaign_verdicts(done: NothingToResume, output: Path, calibration: Path,
                                args: argparse.Namespace) -> int:
    """A complete campaign resumed: the verdicts of the fit this resume did (and its certificates and
    warnings), else those of its calibration file; `--fail-on-reject` either way."""
    from accelcal_rig.fit.campaign_file import calibration_verdicts

    code = 0
    fit = done.fit
    if fit is not None:
        verdicts = fit.verdicts
        for warning in fit.warnings:
            print(f"  warning    {warning}")
        code = _certify_after_run(output, calibration, args)
    else:
        judged = calibration_verdicts(output, calibration)["verdicts"] or {}
        verdicts = {serial: (str(v["verdict"]), tuple(v["reasons"])) for serial, v in judged.items()}
    for serial, (verdict, reasons) in verdicts.items():
        print(f"  verdict    {serial} {verdict}" + (f": {'; '.join(reasons)}" if verdict == "FAIL" else ""))
    rejected = [serial for serial, (verdict, _) in verdicts.items() if verdict == "FAIL"]
    return max(code, _rejected_exit(rejected, args.fail_on_reject))


def _certify_after_run(output: Path, calibration: Path, args: argparse.Namespace) -> int:
    """The certificates at the end of a run; one that cannot be written is one line, the campaign stands."""
    try:
        _certify(output, calibration, args.certificates or output.with_suffix(".certificates"), args.operator,
                 not args.no_pdf)
    except (RigError, OSError) as exc:
        print(f"rig: error: campaign done, but no certificates: {_one_line(exc)}", file=sys.stderr)
        return 1
    return 0


def _certify(campaign: Path, calibration: Path, folder: Path, operator: str, pdf: bool) -> None:
    from accelcal_rig.report.certificate import write_certificates

    written, warnings = write_certificates(campaign, calibration, folder, operator, pdf)
    for warning in warnings:
        print(f"rig: warning: {warning}", file=sys.stderr)
    for w in written:
        print(f"certificate {w.serial} → {w.html}" + (f", {w.pdf.name}" if w.pdf else ""))


def _cmd_export(args: argparse.Namespace) -> int:
    import h5py

    from accelcal_rig.export.flight_stack import StackOptions
    from accelcal_rig.export.formats import export, write_export
    from accelcal_rig.fit.calibration import load_calibration

    if h5py.is_hdf5(args.calibration):  # the campaign, not what a fit of it wrote
        raise ConfigError(f"{args.calibration}: an HDF5 campaign file, not a calibration file: export the calibration "
                          f"YAML that rig fit {args.calibration} -o calibration.yaml (or rig run) writes from it")
    calibration = load_calibration(args.calibration)
    if args.output is not None and not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    exported = export(calibration, args.format, StackOptions(args.calibration, args.serial, args.instance,
                                                             args.device_id))
    return write_export(exported, args.format, args.output)


def _print_fit_table(report: dict) -> None:
    """In-sample figures (the poses fitted) beside verification figures (poses the fit never saw)."""
    print(f"{'':14s} {'raw':>8s} {'in-sample (the fitted poses)':^36s}  {'verification (never fitted)':^33s}".rstrip())
    print(f"{'sensor':14s} {'|g| mg':>8s} {'floor':>7s} {'expected':>8s} {'|g| mg':>7s} {'drift mg':>10s}  "
          f"{'|g| mg':>7s} {'axis mg':>7s} {'tilt °':>7s} {'drift mg':>9s}  {'U k=2 mg':>8s}  verdict")
    for serial, r in report.items():
        v = r.get("verification")
        verification = (f"{v['rmse_mg']:7.4f} {v['max_axis_error_mg']:7.4f} {v['max_tilt_error_deg']:7.4f} "
                        f"{max(v['drift_mg']):9.4f}" if v else f"{'none':>7s} {'':7s} {'':7s} {'':9s}")
        print(f"{serial:14s} {r['rmse_before_mg']:8.3f} {r['noise_floor_mg']:7.4f} {r['expected_fit_rmse_mg']:8.4f} "
              f"{r['rmse_after_mg']:7.4f} {max(r['drift_after_mg']):10.4f}  {verification}  "
              f"{max(r['expanded_uncertainty_mg']):8.4f}  {r['verdict']}")
        for reason in r["verdict_reasons"] if r["verdict"] == "FAIL" else ():
            print(f"  fails: {reason}")
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
    args = build_parser().parse_args(argv)
    # Driver libraries log their own view of a failure; ours is the one line that names the instrument.
    logging.getLogger("pymodbus").addHandler(logging.NullHandler())
    logging.getLogger("pymodbus").propagate = False
    handler = {"run": _cmd_run, "plan": _cmd_plan, "resume": _cmd_resume, "status": _cmd_status, "repair": _cmd_repair,
               "fit": _cmd_fit, "check": _cmd_check,
               "sim": _cmd_sim, "report": _cmd_report, "export": _cmd_export, "certificate": _cmd_certificate,
               "fit-recording": _cmd_fit_recording, "analyze": _cmd_analyze, "registry": _cmd_registry,
               "serve": _cmd_serve, "completion": _cmd_completion}[args.command]
    try:
        return handler(args)
    except CampaignAborted as exc:
        campaign = args.output if args.command == "run" else getattr(args, "campaign", None)
        resume = f"; continue it with: rig resume {campaign}" if campaign is not None else ""
        print(f"rig: campaign aborted, rig in safe state: {_one_line(exc)}{resume}", file=sys.stderr)
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
