"""From a prepared campaign to a finished one: connect (through the rig connector given), create or reopen
the file, run, close — a resumed campaign only with the procedure and rig it began with."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.durable import clear_stale_temporaries
from accelcal_rig.engine.audience import Audience
from accelcal_rig.engine.campaign import CampaignRunner, CampaignSummary, FitOutcome, FitStage
from accelcal_rig.engine.campaign_header import create_campaign_file, fit_attrs, instrument_info
from accelcal_rig.engine.connection import ConnectedRig, RigConnector
from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.notify import Notifier
from accelcal_rig.engine.preparation import PreparedCampaign
from accelcal_rig.engine.progress import ProgressListener
from accelcal_rig.engine.progress_file import ProgressFile
from accelcal_rig.engine.resume import ResumePoint, check_same_campaign
from accelcal_rig.errors import ConfigError, RigError
from accelcal_rig.fit.campaign_fit import fit_and_save, summary_line
from accelcal_rig.fit.fixture_pool import warm_up_workers
from accelcal_rig.fit.recorded_options import recorded_options
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.lock import campaign_lock
from accelcal_rig.store.paths import journal_path, progress_path
from accelcal_rig.store.read import file_currency, load_campaign
from accelcal_rig.store.repair import repair_campaign
from accelcal_rig.store.writer import CampaignWriter


@dataclass(frozen=True)
class RunResult:
    summary: CampaignSummary
    wall_s: float
    output: Path
    #: What closing the campaign could not do (the campaign file left behind its journal), one line each.
    problems: tuple[str, ...] = ()


def run_campaign(prepared: PreparedCampaign, output: Path, connect: RigConnector, *, seed: int, overwrite: bool,
                 calibration: Path | None = None, resume: bool = False,
                 progress: ProgressListener | None = None) -> RunResult:
    """Run the whole campaign into `output` on the rig `connect` connects. Raises CampaignAborted after
    reaching the safe state.

    With `calibration`, the fit stage runs once the rig is safe and writes the calibration file there.
    With `resume` and an existing `output`, the campaign in it continues (see resume_campaign); without
    one, a new campaign starts. `progress` gets a snapshot at every transition, temperature poll and pose;
    the rig config's `notify` is sent events.
    """
    wall_start = time.perf_counter()
    if resume and (output.exists() or journal_path(output).exists()):
        return resume_campaign(prepared, output, connect, calibration=calibration, progress=progress)
    with connect(seed) as rig:
        def create() -> CampaignWriter:
            return create_campaign_file(prepared, output, rig, dry_run=connect.dry_run, seed=seed, overwrite=overwrite)

        return _run(prepared, output, create, rig, None, calibration, wall_start, progress)


class NothingToResume(Exception):
    """The campaign in the file is complete; `fit` is the fit this resume did for it (None: none was due)."""

    def __init__(self, message: str, fit: FitOutcome | None = None) -> None:
        super().__init__(message)
        self.fit = fit


def resume_campaign(prepared: PreparedCampaign, output: Path, connect: RigConnector, *,
                    calibration: Path | None = None, progress: ProgressListener | None = None) -> RunResult:
    """Continue the campaign in `output`: the same procedure and rig (refused otherwise, before anything is
    touched), the journal mended and the campaign file rebuilt from it, the rig made safe first if the
    last run died, then a fresh soak at the first setpoint with poses missing and on from the first pose
    not stored."""
    wall_start = time.perf_counter()
    stored = load_campaign(output)
    dry_run = connect.dry_run
    check_same_campaign(output, stored, prepared.procedure, prepared.rig, prepared.plan, dry_run)
    if stored.state == "done" and stored.poses_planned == len(stored.poses):
        done, fit = _finish_complete(prepared, output, stored, calibration)
        raise NothingToResume("; ".join([f"{output}: the campaign is complete: every pose is stored", *done]), fit)
    writer, reopened = CampaignWriter.reopen(output, prepared.storage(dry_run))
    try:
        # Noise of a resumed dry run is new noise (the same sensors, not a replay of the first run).
        seed = int(stored.attrs.get("seed", 0)) + 1000 * (reopened.run - 1)
        with connect(seed, reopened.clock_now_s) as rig:
            writer.record_instruments(instrument_info(rig.instruments, prepared.rig.model))
            point = ResumePoint(frozenset(writer.stored_step_keys()), reopened.previous_state in ("created", "running"),
                                reopened.run)
            events = EventLog(rig.clock, writer)
            events.info("resume", f"run {reopened.run} resumes after {reopened.poses_stored} stored poses (the last run "
                                  f"left the file {reopened.previous_state!r})")
            for repair in reopened.repairs:
                events.warning("resume", repair)
            return _run(prepared, output, lambda: writer, rig, point, calibration, wall_start, progress)
    finally:
        _close(writer)


def _finish_complete(prepared: PreparedCampaign, output: Path, stored: Campaign,
                     calibration: Path | None) -> tuple[list[str], FitOutcome | None]:
    """What a complete campaign may still lack after a full disk or a kill at its very end: a campaign
    file as current as its journal, its calibration file. Done now; (what was done, one line each; the fit
    done, if one was)."""
    done, fit = [], None
    with campaign_lock(output, "rig resume"):
        clear_progress(output)
        if file_currency(output, stored, writing=False) != "current":
            repair_campaign(output)
            done.append(f"{output.name} brought up to date from its journal")
        if calibration is not None and prepared.procedure.model.fit.mode != "none" and not _fitted_to(calibration, output):
            try:
                fit = _fit_stage(prepared.procedure.model, output, calibration)(load_campaign(output))
            except (ValueError, KeyError, OSError, np.linalg.LinAlgError) as exc:
                raise RigError(f"{output}: the campaign is complete, but its fit failed: {exc}") from None
            done.append(fit.summary)
    return done, fit


def clear_progress(output: Path) -> None:
    """The campaign's progress view and its half-written versions, left by a run that was killed: removed
    by the next command that holds the campaign (never shown as a live run's)."""
    clear_stale_temporaries(progress_path(output))
    progress_path(output).unlink(missing_ok=True)


def _fitted_to(calibration: Path, output: Path) -> bool:
    """Whether the calibration file is there, readable and fitted to the campaign's measurements now (else a
    complete campaign's resume fits it again: the file is derived, like the campaign file)."""
    from accelcal_rig.fit.calibration import load_calibration
    from accelcal_rig.store.content import measurements_sha256

    if not calibration.is_file():
        return False
    try:
        fitted = load_calibration(calibration).source.get("measurements_sha256")
    except ConfigError:
        return False
    return fitted == measurements_sha256(load_campaign(output))


def _close(writer: CampaignWriter) -> tuple[str, ...]:
    """Close the campaign; what closing could not do is logged and returned, the run's outcome stands."""
    problems = tuple(writer.close())
    for problem in problems:
        LOGGER.error(problem)
    return problems


def _run(prepared: PreparedCampaign, output: Path, open_writer: Callable[[], CampaignWriter],
         rig_connected: ConnectedRig, resume: ResumePoint | None, calibration: Path | None, wall_start: float,
         progress: ProgressListener | None) -> RunResult:
    """The campaign from its file's opening to its closing: the runner opens the file, and any stop once it
    is open ends safe and recorded."""
    procedure, rig = prepared.procedure.model, prepared.rig.model
    notify = rig.notify
    estimate = estimate_duration(procedure, rig, prepared.plan)
    fit_stage = _fit_stage(procedure, output, calibration) if calibration and procedure.fit.mode != "none" else None
    if fit_stage is not None:
        warm_up_workers(len(rig.fixture.sensors))  # a large fixture's fit workers load while it measures
    notifier = Notifier(notify) if notify.webhook_url or notify.command else None
    clear_progress(output)
    audience = Audience(ProgressFile(progress_path(output), progress), estimate, notifier, str(output))
    runner = CampaignRunner(procedure, rig, prepared.plan, rig_connected, open_writer, fit_stage=fit_stage,
                            resume=resume, audience=audience)
    problems: tuple[str, ...] = ()
    try:
        summary = runner.run()
    finally:
        try:
            if runner.writer is not None:
                progress_path(output).unlink(missing_ok=True)  # a view of this run only: gone with it
                problems = _close(runner.writer)
        finally:
            if notifier is not None:  # the fault, safe and finish events still go out
                notifier.close()
    return RunResult(summary, time.perf_counter() - wall_start, output, problems)


def _fit_stage(procedure: Procedure, output: Path, calibration: Path) -> FitStage:
    options = recorded_options(fit_attrs(procedure), f"{output}: its procedure's fit")
    assert options is not None, "a procedure without a fit has no fit stage"

    def stage(campaign: Campaign) -> FitOutcome:
        fitted, report = fit_and_save(campaign, output, calibration, options, run_end=True)
        return FitOutcome(summary_line(report, calibration),
                          {serial: (r["verdict"], tuple(r["verdict_reasons"])) for serial, r in report.items()},
                          tuple(f"sensor {serial}{'' if len(r['channels']) == 1 else ' ' + channel}: {w}"
                                for serial, r in report.items() for channel, figures in r["channels"].items()
                                for w in figures["warnings"])
                          + tuple(f"sensor {serial}: not fitted, no calibration or certificate: {why}"
                                  for serial, why in fitted.dropped.items()))

    return stage
