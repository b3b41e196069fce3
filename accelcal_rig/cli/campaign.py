"""The work behind `rig run`, `rig resume`, `rig status` and `rig sim` that is not the engine's: the
campaign's files checked and its procedure prepared from the command line, the signal handling and the
logging a run has on the console and in its log file, the lock and the free-space check around it."""

from __future__ import annotations

import argparse
import datetime as dt
import logging
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, stop_when_safe
from accelcal_rig.errors import ConfigError

if TYPE_CHECKING:
    from accelcal_rig.cli.follow_up import FollowUp
    from accelcal_rig.config.lab import Receipt
    from accelcal_rig.engine.preparation import PreparedCampaign
    from accelcal_rig.engine.progress import Progress, ProgressListener
    from accelcal_rig.registry.publisher import LivePublisher


def prepare_run(args: argparse.Namespace) -> tuple[PreparedCampaign, bool]:
    """`rig run`'s campaign prepared, its output checked; and whether it continues the file there (--resume)."""
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
    prepared = replace(prepare(args.procedure, args.config, args.faults, profile), receipt=_receipt(args))
    _received_before(prepared, args.today())
    if exists and not (args.overwrite or args.resume):
        raise ConfigError(f"{args.output}: campaign file exists; continue it with --resume, or choose another -o "
                          "or pass --overwrite")
    if not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    return prepared, args.resume and exists


def _receipt(args: argparse.Namespace) -> Receipt:
    """`rig run --customer/--received/--condition`: what a new campaign records of the DUTs that state none."""
    from accelcal_rig.config.lab import Receipt, iso_date

    try:
        received = iso_date(args.received) if args.received else None
    except ValueError as exc:
        raise ConfigError(f"--received: {exc}") from None
    for option, text, longest in (("--customer", args.customer, 200), ("--contact", args.contact, 200),
                                  ("--condition", args.condition, 500), ("--lot", args.lot, 64)):
        if len(text) > longest or any(ord(c) < 32 or ord(c) == 127 for c in text):
            raise ConfigError(f"{option}: not one line of at most {longest} characters")
    return Receipt(customer=args.customer, received_date=received, condition=args.condition, lot=args.lot,
                   contact=args.contact)


def _received_before(prepared: PreparedCampaign, today: dt.date) -> None:
    """An item is received before it is calibrated: a date of receipt after today's is refused, naming its key."""
    for index, sensor in enumerate(prepared.rig.model.fixture.sensors):
        received, key = ((sensor.received_date, f"fixture.sensors[{index}].received_date ({sensor.serial})")
                         if sensor.received_date is not None else (prepared.receipt.received_date, "--received"))
        if received is not None and received > today:
            where = f"{prepared.rig.path}: " if key.startswith("fixture") else ""
            raise ConfigError(f"{where}{key}: {received.isoformat()} is after the calibration ({today.isoformat()}): "
                              "an item is received before it is calibrated")


def prepare_resume(args: argparse.Namespace) -> tuple[PreparedCampaign, bool, int]:
    """`rig resume`'s campaign prepared from the procedure it was started with; whether it is a dry run, its seed."""
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(args.campaign)
    procedure = args.procedure or Path(str(stored.attrs.get("procedure_path", "")))
    if not procedure.is_file():
        raise ConfigError(f"{args.campaign}: its procedure {procedure} is gone; pass --procedure with the same "
                          "procedure")
    prepared = prepare(procedure, args.config, args.faults, str(stored.attrs.get("chamber_profile", "")) or None)
    return prepared, bool(stored.attrs.get("dry_run", False)), int(stored.attrs.get("seed", 0))


def calibration_path(given: Path | None, output: Path) -> Path:
    """The calibration file a run's fit writes: --calibration, else beside the campaign; its folder checked."""
    calibration = given or output.with_suffix(".calibration.yaml")
    if not calibration.parent.is_dir():
        raise ConfigError(f"{calibration}: folder {calibration.parent} does not exist")
    return calibration


def follow_up_of(args: argparse.Namespace, output: Path, continuing: bool, registry: str | None = None) -> FollowUp:
    """Where this command writes the campaign's follow-up: a new campaign's from its flags (recorded in it), a
    continued one's as its `rig run` recorded, each part a flag names now instead."""
    from accelcal_rig.cli import follow_up
    from accelcal_rig.store.paths import journal_path
    from accelcal_rig.store.read import load_campaign

    calibration_path(args.calibration, output)  # a folder named and missing: refused before anything moves
    if continuing and (output.exists() or journal_path(output).exists()):
        found = follow_up.of_campaign(load_campaign(output).attrs, output, args)
        calibration_path(found.calibration, output)
        return found
    return follow_up.of_run(args, output, calibration_path(args.calibration, output), registry)


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


@contextmanager
def stop_on_first_signal() -> Iterator[None]:
    """While a campaign runs: the first SIGINT or SIGTERM stops it when safe, later ones are logged and ignored."""
    stop = _StopOnFirstSignal()
    previous = {signum: signal.signal(signum, stop) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


@contextmanager
def until_signalled() -> Iterator[threading.Event]:
    """An event SIGINT or SIGTERM sets (`rig sim` serves until then)."""
    stop = threading.Event()
    previous = {signum: signal.signal(signum, lambda *_: stop.set()) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield stop
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


@contextmanager
def campaign_session(prepared: PreparedCampaign, output: Path, *, verbose: bool, quiet: bool, dry_run: bool,
                     overwrite: bool, resume: bool) -> Iterator[ProgressListener]:
    """Around a run: the campaign locked before anything of it changes (the log included), a new campaign's
    disk space checked, the console and the log file attached; yields the progress listener. A run that
    fails before its campaign starts (a dead port, a refused instrument) leaves no file it made: its log is
    not written and a lock file it created is removed."""
    from accelcal_rig.store.lock import campaign_lock
    from accelcal_rig.store.paths import lock_path

    made_lock = not lock_path(output).exists()
    before = _footprint(output)
    with campaign_lock(output, "rig resume" if resume else "rig run"):
        try:
            if not resume:
                check_free_space(prepared, output, dry_run, overwrite)
            with campaign_logging(output, verbose, quiet, append=resume, real_clock=not dry_run,
                                  started=lambda: _footprint(output) != before) as progress:
                yield progress
        finally:
            if made_lock and _footprint(output) == before:
                _remove_lock(output)


def _footprint(output: Path) -> tuple[tuple[int, int, int] | None, ...]:
    """What a run changes once its campaign starts: the campaign file and its journal (inode, size, time)."""
    from accelcal_rig.store.paths import journal_path

    def identity(path: Path) -> tuple[int, int, int] | None:
        try:
            info = path.stat()
        except OSError:
            return None
        return info.st_ino, info.st_size, info.st_mtime_ns

    return identity(output), identity(journal_path(output))


def _remove_lock(output: Path) -> None:
    """Remove the lock file this run made, while still holding it (store.lock: a writer that then locks the
    removed file sees it is gone and locks the new one)."""
    from accelcal_rig.store.lock import remove_lock_file

    remove_lock_file(output)


def check_free_space(prepared: PreparedCampaign, output: Path, dry_run: bool, overwrite: bool) -> None:
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


@contextmanager
def campaign_logging(output: Path, verbose: bool, quiet: bool, append: bool, real_clock: bool,
                     started: Callable[[], bool] = lambda: True) -> Iterator[ProgressListener]:
    """Console on stderr at the chosen level (a live status line on a terminal, timestamped lines
    otherwise), the full debug log with progress lines in a file beside the campaign file (appended to by
    a resumed run); yields the progress listener. The file is written from the first progress of the
    campaign on, with what was logged before it; a run whose campaign never started (`started()` false at
    the end) writes none unless it appends to a log already there. Everything is detached and closed when
    the run ends."""
    from accelcal_rig.report.live import CampaignLog, ProgressLines, StatusLine, TerminalHandler, listeners
    from accelcal_rig.store.paths import log_path

    _check_log_writable(log_path(output))
    status = StatusLine(sys.stderr, real_clock) if sys.stderr.isatty() and not quiet else None
    console: logging.Handler
    if status is not None:
        console = TerminalHandler(status)
        console.setFormatter(logging.Formatter("%(message)s"))
    else:
        console = logging.StreamHandler(sys.stderr)
        console.setFormatter(logging.Formatter("%(asctime)s %(levelname)-7s %(message)s", "%Y-%m-%d %H:%M:%S"))
    console.setLevel(logging.DEBUG if verbose else logging.WARNING if quiet else logging.INFO)
    log_file = CampaignLog(str(log_path(output)), mode="a" if append else "w")
    log_file.setFormatter(logging.Formatter("%(asctime)s %(levelname)-7s %(message)s"))
    LOGGER.setLevel(logging.DEBUG)
    propagate, LOGGER.propagate = LOGGER.propagate, False
    for handler in (console, log_file):
        LOGGER.addHandler(handler)
    lines = ProgressLines(real_clock)

    def first_progress_starts_the_log(progress: Progress) -> None:
        log_file.start()
        lines(progress)

    try:
        yield (listeners(first_progress_starts_the_log, status) if status is not None
               else first_progress_starts_the_log)
    finally:
        if status is not None:
            status.close()
        if append or started():
            log_file.start()
        else:
            log_file.discard()
        for handler in (console, log_file):
            LOGGER.removeHandler(handler)
            handler.close()
        LOGGER.propagate = propagate


def _check_log_writable(log: Path) -> None:
    """Refuse before the run a log that could not be written (its folder or the file read-only), without
    making it: the file itself is made once the campaign starts."""
    import os

    target = log if log.exists() else log.parent
    if not os.access(target, os.W_OK):
        raise ConfigError(f"{log}: cannot write the campaign's log: permission denied")


def campaign_status(campaign: Path, calibration: Path | None) -> dict[str, Any]:
    """`rig status --json`: the campaign's state and progress, its DUTs' verdicts from its calibration, each
    part of its follow-up (calibration, certificates, registry) with what is missing, and every DUT the early
    check flagged (`early_check`: serial, setpoint_c, finding, value, limit, action, and a dead axis's axis)."""
    from accelcal_rig.cli import follow_up
    from accelcal_rig.fit.campaign_file import calibration_verdicts
    from accelcal_rig.fit.early_check import logged_findings
    from accelcal_rig.fit.recorded_options import NO_FIT, requested_mode
    from accelcal_rig.store.read import campaign_status as stored_status
    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(campaign)
    found = follow_up.of_campaign(stored.attrs, campaign, argparse.Namespace(calibration=calibration))
    fit_due = requested_mode(stored.attrs) != NO_FIT
    parts = follow_up.state(campaign, found, fit_due)
    return {**stored_status(campaign, stored), **calibration_verdicts(campaign, found.calibration),
            "follow_up": [p.as_dict() for p in parts],
            "early_check": [f.as_dict() for f in logged_findings(stored.events)]}


@contextmanager
def live_publishing(prepared: PreparedCampaign, output: Path, follow_up: FollowUp, *, dry_run: bool, fresh: bool,
                    enabled: bool) -> Iterator[LivePublisher | None]:
    """The campaign's live status published to the registry its calibrations go to (a dry run's to the dry
    runs' own), from its first progress to its last word: how it ended, each DUT's verdict once judged. Yields
    the publisher (None with `rig run --no-publish`), whose events come from the log."""
    from accelcal_rig.registry.location import configured, recording_url
    from accelcal_rig.registry.publisher import Identity, LivePublisher

    if not enabled:
        yield None
        return
    url = recording_url(follow_up.registry or follow_up.recorded_registry,
                        configured(prepared.rig.model.registry, prepared.rig.path), dry_run)
    identity = Identity(prepared.rig.model.name, output.resolve(), prepared.procedure.model.name, dry_run)
    publisher = LivePublisher(url, identity, fresh)
    handler = publisher.handler()
    LOGGER.addHandler(handler)
    try:
        yield publisher
    finally:
        LOGGER.removeHandler(handler)
        try:
            if publisher.started and not publisher.finished:  # a run that ended without its summary: read the file
                publisher.finish(**_last_word(output, follow_up))
            problem = publisher.close()
        except (KeyboardInterrupt, TerminationRequested):  # the campaign has ended: only its view is cut short
            problem = "live status: interrupted before the campaign's last state was published (its campaign file has it)"
        if problem is not None:
            print(f"rig: warning: {problem}", file=sys.stderr)


def _last_word(output: Path, follow_up: FollowUp) -> dict[str, Any]:
    """How the campaign in `output` stands now, for its live status: its state, its poses, its verdicts."""
    from accelcal_rig.fit.campaign_file import calibration_verdicts
    from accelcal_rig.store.read import load_campaign

    try:
        campaign = load_campaign(output)
        verdicts = calibration_verdicts(output, follow_up.calibration)["verdicts"] if campaign.state == "done" else None
    except Exception as exc:  # noqa: BLE001 - a view: a file that cannot be read now is said so, not raised
        return {"state": "stopped", "abort_reason": f"campaign file unreadable: {str(exc).splitlines()[0]}"}
    state = campaign.state if campaign.state in ("done", "aborted") else "stopped"
    return {"state": state, "poses_done": len(campaign.poses), "verdicts": verdicts,
            "abort_reason": campaign.abort_reason or ""}
