"""`rig`: the command line. Every failure a user can cause is one line on stderr and a non-zero exit.

Each command parses (the grammar: `parser.py`, `grammar/`), calls one function and prints what it returns,
formatted beside what it formats (`status_text.py`, `format_*.py`); the work of a command lives below it
(`run_end.py`, `campaign.py`, `recording.py`, `serve.py`, `registry.py`, `analyze.py`, the assembly, the
engine)."""

from __future__ import annotations

import argparse
import datetime as dt
import json
import logging
import os
import shlex
import signal
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from accelcal_rig.cli.outcome import EXIT_CHECK_FAILED, EXIT_INTERNAL, EXIT_INTERRUPTED, one_line
from accelcal_rig.cli.parser import build_parser
from accelcal_rig.cli.run_end import certify, execute, record, rejected_exit
from accelcal_rig.core.signals import TerminationRequested
from accelcal_rig.errors import CampaignAborted, ConfigError, RigError

if TYPE_CHECKING:
    from accelcal_rig.engine.preparation import PreparedCampaign

def _cmd_run(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.campaign import prepare_run

    prepared, resume = prepare_run(args)
    _warn_of_references(prepared, args)
    return execute(prepared, args.output, args, dry_run=args.dry_run, seed=args.seed, overwrite=args.overwrite,
                    resume=resume)


def _cmd_plan(args: argparse.Namespace) -> int:
    from accelcal_rig.engine.estimate import estimate_duration
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.report.plan_summary import plan_json, plan_lines

    prepared = prepare(args.procedure, args.config)
    _warn_of_references(prepared, args)
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    if args.json:
        print(json.dumps(plan_json(prepared, estimate)))
    else:
        print("\n".join(plan_lines(prepared, estimate)))
    return 0


def _cmd_resume(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.campaign import prepare_resume

    prepared, dry_run, seed = prepare_resume(args)
    _warn_of_references(prepared, args)
    return execute(prepared, args.campaign, args, dry_run=dry_run, seed=seed, overwrite=False, resume=True)


def _warn_of_references(prepared: PreparedCampaign, args: argparse.Namespace) -> None:
    """A line on stderr for each of the rig's references past its due date (refused instead, in one line, when
    the rig config says `references_overdue: refuse`), before anything moves."""
    from accelcal_rig.config.traceability import reference_warnings

    for line in reference_warnings(prepared.rig, args.today()):
        print(f"rig: warning: {line}", file=sys.stderr)


def _cmd_status(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.campaign import campaign_status
    from accelcal_rig.cli.status_text import status_lines

    if args.watch:
        return _watch_status(args)
    status = campaign_status(args.campaign, args.calibration)
    print(json.dumps(status) if args.json else "\n".join(status_lines(status)))
    return 0


def _watch_status(args: argparse.Namespace) -> int:
    """`rig status --watch`: again every so many seconds, until the campaign ends or Ctrl-C."""
    import time

    from accelcal_rig.cli.campaign import campaign_status
    from accelcal_rig.cli.status_text import watch_text

    try:
        while True:
            status = campaign_status(args.campaign, args.calibration)
            print(json.dumps(status) if args.json else watch_text(status, args.watch, sys.stdout.isatty()), flush=True)
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
    from accelcal_rig.assembly import checked
    from accelcal_rig.cli.format_campaign import check_closing_line, check_failed_line, check_line, check_names
    from accelcal_rig.config.load import load_rig, load_rig_for_check, with_faults

    only = frozenset(args.only or ("chamber", "turntable", "sensors"))
    rig = with_faults(load_rig_for_check(args.rig, only) if args.only else load_rig(args.rig), args.faults)
    names = check_names(rig.model, only)
    failed = []
    for instrument in checked(rig, dry_run=args.dry_run, only=only):
        print(check_line(instrument, max(map(len, names))), flush=True)
        if not instrument.ok:
            failed.append(instrument.name)
    if failed:
        print(check_failed_line(rig.model.name, failed, len(names)), file=sys.stderr)
        return EXIT_CHECK_FAILED
    print(check_closing_line(rig.model.name, only if args.only else None))
    return 0


def _cmd_characterise(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.characterise import characterise, characterise_json, characterise_lines
    from accelcal_rig.config.write_thermal import write_thermal

    result = characterise(args.campaign)
    if args.write is not None:
        write_thermal(args.write, result.thermal(), result.measured())
    if args.json:
        print(json.dumps({**characterise_json(result), "written": str(args.write) if args.write else None}))
    else:
        print("\n".join(characterise_lines(result)))
        print(f"written    thermal: in {args.write} (its other lines as they were)" if args.write is not None
              else f"write them into the rig config with: rig characterise {args.campaign} --write RIG")
    return 0


def _cmd_sim(args: argparse.Namespace) -> int:
    from accelcal_rig.assembly import served_rig
    from accelcal_rig.cli.campaign import until_signalled
    from accelcal_rig.cli.format_campaign import sim_stopped_line
    from accelcal_rig.config.load import load_rig, with_chamber_profile, with_faults
    from accelcal_rig.core.clock import RealClock

    described = None
    try:
        rig = with_chamber_profile(with_faults(load_rig(args.rig), args.faults), args.chamber_profile)
        with until_signalled() as stop, served_rig(rig.model, RealClock(), args.seed) as simulated:
            described = simulated.describe()
            print(json.dumps(described), flush=True)
            while not stop.wait(0.5):
                pass
    except (KeyboardInterrupt, TerminationRequested):
        pass  # a signal before the simulators took it over: stopped as well
    print(sim_stopped_line(args.rig, described), file=sys.stderr)
    return 0


def _cmd_fit(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.format_fit import fit_lines
    from accelcal_rig.cli.registry_access import campaign_entries, stored_rig_registry
    from accelcal_rig.fit.campaign_file import fit_campaign_file

    outcome = fit_campaign_file(args.campaign, args.output, partial=args.partial, mode=args.mode, degree=args.degree,
                                free=args.parameters, out_of_range=args.out_of_range,
                                temperature_model=args.temperature_model)
    for warning in outcome.warnings:
        print(f"rig: warning: {warning}", file=sys.stderr)
    print(json.dumps(outcome.report) if args.json else "\n".join(fit_lines(outcome.report, args.output)))
    if outcome.ended:  # a partial fit is never a serial's calibration, nor masks one: not recorded
        record(args.registry, stored_rig_registry(args.campaign), args.campaign,
               lambda: campaign_entries(args.campaign, args.output), args.json)
    rejected = [serial for serial, r in outcome.report.items() if r["verdict"] == "FAIL"]
    return rejected_exit(rejected, args.fail_on_reject)


def _cmd_fit_recording(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.format_fit import recording_lines
    from accelcal_rig.cli.recording import calibrate_recording
    from accelcal_rig.cli.registry_access import recording_entries

    recording, result = calibrate_recording(args)
    print(json.dumps(result.report) if args.json else "\n".join(recording_lines(
        result.report, recording.source, threshold_factor=args.threshold_factor, init_s=args.init_s,
        output=args.output, parameters=args.parameters)))
    record(args.registry, None, args.recording,
            lambda: recording_entries(args.recording, result.calibration, args.part, recording.simulated),
            json_output=args.json, later="run this rig fit-recording again once the registry is reachable")
    return 0


def _cmd_completion(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.parser import bash_completion

    sys.stdout.write(bash_completion(build_parser()))
    return 0


def _cmd_init(args: argparse.Namespace) -> int:
    from accelcal_rig.config.starter import write_starter

    written = write_starter(args.folder)
    folders = sorted({path.parent.name for path in written if path.parent != args.folder})
    print(f"wrote {len(written)} files into {args.folder}: README.md, {', '.join(f + '/' for f in folders)}")
    print(f"next: cd {shlex.quote(str(args.folder))} && rig run procedures/paper-24pos-thermal.yaml --dry-run -o paper.h5")
    return 0


def _cmd_schema(args: argparse.Namespace) -> int:
    from accelcal_rig.config.schemas import schema_text
    from accelcal_rig.durable import write_text_atomically

    text = schema_text(args.kind)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    write_text_atomically(args.output, text, "the schema")
    print(f"{args.kind} schema → {args.output}")
    return 0


def _cmd_serve(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.serve import open_dashboard, stop_requests, stopped_line, stops_ignored

    dashboard = None
    try:
        with stop_requests() as stops:  # SIGINT or SIGTERM: how a dashboard is meant to end
            dashboard = open_dashboard(args)
            print(f"dashboard on {dashboard.url}", flush=True)
            dashboard.serve(stops)
    except (KeyboardInterrupt, TerminationRequested):
        pass  # a stop from elsewhere (a thread that is not the main one cannot take signals)
    with stops_ignored():  # a second Ctrl-C as it says so is the same request
        print(stopped_line(dashboard), file=sys.stderr)
    return 0


def _cmd_registry(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.registry import registry_command

    return registry_command(args)


def _cmd_approve(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.approval import approve_command

    return approve_command(args)


def _cmd_analyze(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.analyze import analyze

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
    certify(args.campaign, calibration, args.output, args.operator, not args.no_pdf)
    return 0


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


#: Commands a signal is the way to end (what they serve stops: exit 0), not a campaign interrupted.
_ENDED_BY_SIGNAL = ("serve", "sim")


def _interrupted(command: str | None) -> int:
    """Say what a signal outside a command's own handling stopped; its exit code."""
    if command in _ENDED_BY_SIGNAL:
        print(f"rig {command}: stopped", file=sys.stderr)
        return 0
    print("rig: interrupted before the campaign started; nothing was moved", file=sys.stderr)
    return EXIT_INTERRUPTED


def run_program() -> None:
    """The `rig` executable: run the command, then exit without letting a late signal crash the exit.

    By the time a command returns, its campaign is recorded (done, or aborted and safe); a second
    Ctrl-C arriving while the interpreter shuts down must not turn that into a kill by signal. SIGTERM is Ctrl-C
    from the start, as the `rig` script (accelcal_rig.entry) makes it, under `python -m accelcal_rig` too.
    """
    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, interrupt)
    try:
        code = main()
    except KeyboardInterrupt:  # a signal between start and the command's own handling
        code = _interrupted(next((word for word in sys.argv[1:] if not word.startswith("-")), None))
    except BrokenPipeError:  # `rig status … | head`: the reader has gone; so has the need to print
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 0
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise SystemExit(code)


def main(argv: list[str] | None = None, today: Callable[[], dt.date] = dt.date.today) -> int:
    """`today`: the calendar the references' due dates are judged by (a test passes its own)."""
    args = build_parser().parse_args(argv)
    args.today = today
    # Driver libraries log their own view of a failure; ours is the one line that names the instrument.
    logging.getLogger("pymodbus").addHandler(logging.NullHandler())
    logging.getLogger("pymodbus").propagate = False
    handler = {"run": _cmd_run, "plan": _cmd_plan, "resume": _cmd_resume, "status": _cmd_status, "repair": _cmd_repair,
               "fit": _cmd_fit, "check": _cmd_check, "characterise": _cmd_characterise,
               "sim": _cmd_sim, "report": _cmd_report, "export": _cmd_export, "certificate": _cmd_certificate,
               "fit-recording": _cmd_fit_recording, "analyze": _cmd_analyze, "registry": _cmd_registry,
               "serve": _cmd_serve, "completion": _cmd_completion, "schema": _cmd_schema, "init": _cmd_init,
               "approve": _cmd_approve}[args.command]
    try:
        return handler(args)
    except CampaignAborted as exc:
        campaign = args.output if args.command == "run" else getattr(args, "campaign", None)
        resume = f"; continue it with: rig resume {campaign}" if campaign is not None else ""
        print(f"rig: campaign aborted, rig in safe state: {one_line(exc)}{resume}", file=sys.stderr)
        interrupted = isinstance(exc.__cause__, (KeyboardInterrupt, TerminationRequested))
        return EXIT_INTERRUPTED if interrupted else exc.exit_code
    except RigError as exc:
        print(f"rig: error: {one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except (KeyboardInterrupt, TerminationRequested):
        return _interrupted(args.command)
    except Exception as exc:  # noqa: BLE001 - a bug still reaches the operator as one line, not a traceback
        if os.environ.get("RIG_TRACEBACK") or isinstance(exc, BrokenPipeError):
            raise
        detail = str(exc).strip().splitlines()
        print(f"rig: internal error: {type(exc).__name__}{': ' + detail[0] if detail else ''} (a bug in accelcal-rig; "
              "please report it with the command; RIG_TRACEBACK=1 shows where)", file=sys.stderr)
        return EXIT_INTERNAL
