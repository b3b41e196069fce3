"""What follows a campaign's run or resume on the command line: the run under its signal handling, logging and
live status, its summary and verdicts, then its follow-up (the certificates and the registry rows), each
written only where it is not there and current; and the registry recording `rig fit` shares."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from accelcal_rig.cli.outcome import EXIT_INTERRUPTED, EXIT_NOT_RECORDED, EXIT_REJECTED, one_line
from accelcal_rig.core.signals import TerminationRequested
from accelcal_rig.errors import RigError

if TYPE_CHECKING:
    from accelcal_rig.cli.follow_up import FollowUp
    from accelcal_rig.engine.preparation import PreparedCampaign
    from accelcal_rig.engine.session import NothingToResume, RunResult
    from accelcal_rig.registry.publisher import LivePublisher


def execute(prepared: PreparedCampaign, output: Path, args: argparse.Namespace, *, dry_run: bool, seed: int,
             overwrite: bool, resume: bool) -> int:
    """Run or resume under the CLI's signal handling and logging, the campaign locked before anything of it
    changes (the log included); print the summary, then finish the campaign's follow-up."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.cli.campaign import campaign_session, follow_up_of, live_publishing, stop_on_first_signal
    from accelcal_rig.engine.session import NothingToResume
    from accelcal_rig.registry.location import configured, recording_url
    from accelcal_rig.report.live import listeners

    # The registry this run records in, however it is named: kept in the campaign for its resume.
    recorded = recording_url(args.registry, configured(prepared.rig.model.registry, prepared.rig.path), dry_run)
    follow_up = follow_up_of(args, output, resume and not overwrite, recorded)
    prepared = replace(prepared, follow_up=follow_up.to_json())
    with live_publishing(prepared, output, follow_up, dry_run=dry_run, fresh=not resume,
                         enabled=not args.no_publish) as publisher:
        with stop_on_first_signal():
            try:
                with campaign_session(prepared, output, verbose=args.verbose, quiet=args.quiet, dry_run=dry_run,
                                      overwrite=overwrite, resume=resume) as progress:
                    watched = listeners(progress, publisher) if publisher is not None else progress
                    result = run_campaign(prepared, output, dry_run=dry_run, seed=seed, overwrite=overwrite,
                                          calibration=follow_up.calibration, resume=resume, progress=watched)
            except NothingToResume as done:
                print(done)
                code = _complete_campaign_verdicts(done, output, follow_up, args)
                if publisher is not None:  # its card ends as the campaign did, whatever its last run published
                    publish_final_state(publisher, output, follow_up)
                return code
        code = _after_campaign(prepared, result, output, follow_up, args, dry_run)
        if publisher is not None:  # the run's own account: its file need not be read again
            summary = result.summary
            publisher.finish(summary.state, summary.poses_done, {
                serial: {"verdict": verdict, "reasons": list(reasons)} for serial, (verdict, reasons) in summary.verdicts.items()})
        return code


def _after_campaign(prepared: PreparedCampaign, result: RunResult, output: Path, follow_up: FollowUp,
                    args: argparse.Namespace, dry_run: bool) -> int:
    """The summary; after a fit, the certificates and the registry. A signal now only cuts the printing short."""
    try:
        code = _print_summary(prepared, result, dry_run, args.fail_on_reject)
        if result.summary.fit and not result.summary.fit_failed:
            code = max(code, _finish_follow_up(output, follow_up))
        return code
    except (KeyboardInterrupt, TerminationRequested):
        print(f"rig: interrupted after the campaign ended ({result.summary.state}); {result.output} holds all of it",
              file=sys.stderr)
        return EXIT_INTERRUPTED


def _print_summary(prepared: PreparedCampaign, result: RunResult, dry_run: bool, fail_on_reject: bool) -> int:
    from accelcal_rig.cli.format_campaign import run_summary_lines

    summary = result.summary
    print("\n".join(run_summary_lines(prepared, result, dry_run)))
    if summary.fit_failed:
        print(f"rig: campaign done but the fit failed: {one_line(Exception(summary.fit))}", file=sys.stderr)
        return 1
    if result.problems:
        print(f"rig: error: campaign done, but {result.problems[0]}", file=sys.stderr)
        return 1
    return rejected_exit(summary.rejected, fail_on_reject)


def _complete_campaign_verdicts(done: NothingToResume, output: Path, follow_up: FollowUp,
                                args: argparse.Namespace) -> int:
    """A complete campaign resumed: the verdicts of the fit this resume did (and its warnings), else those of
    its calibration file; then whatever of its certificates and registry rows is missing; `--fail-on-reject`
    either way."""
    from accelcal_rig.cli.format_campaign import verdict_lines, warning_lines
    from accelcal_rig.fit.campaign_file import calibration_verdicts

    fit = done.fit
    if fit is not None:
        verdicts = fit.verdicts
        for line in warning_lines(fit.warnings):
            print(line)
    else:
        judged = calibration_verdicts(output, follow_up.calibration)["verdicts"] or {}
        verdicts = {serial: (str(v["verdict"]), tuple(v["reasons"])) for serial, v in judged.items()}
    for line in verdict_lines(verdicts):
        print(line)
    code = _finish_follow_up(output, follow_up) if follow_up.calibration.is_file() else 0
    rejected = [serial for serial, (verdict, _) in verdicts.items() if verdict == "FAIL"]
    return max(code, rejected_exit(rejected, args.fail_on_reject))


def _finish_follow_up(output: Path, follow_up: FollowUp) -> int:
    """The certificates and the registry rows of a fitted campaign, each written only if it is not there and
    current (follow_up.state): a run's, or what a kill left undone of one."""
    from accelcal_rig.cli import follow_up as follow
    from accelcal_rig.cli.registry_access import campaign_entries
    from accelcal_rig.registry.location import campaign_rig_registry

    parts = {p.part: p for p in follow.state(output, follow_up)}
    calibration = parts.get("calibration")
    if calibration is None or calibration.state != follow.DONE:  # nothing to certify or record from
        if calibration is not None and calibration.state != follow.NOT_DUE:
            print(f"rig: error: no certificates or registry rows: calibration {calibration.state}: "
                  f"{calibration.detail}", file=sys.stderr)
            return 1
        return 0
    code = 0
    if parts["certificates"].state != follow.DONE:
        code = _certify_after_run(output, follow_up)
    if parts["registry"].state == follow.DONE:
        print(f"registry   {parts['registry'].detail} already")
    elif not record(follow_up.registry, campaign_rig_registry(output), output,
                    lambda: campaign_entries(output, follow_up.calibration),
                    later=f"rig resume {output} will record them, or rig registry add {output}",
                    recorded=follow_up.recorded_registry):
        code = max(code, EXIT_NOT_RECORDED)
    return code


def record(flag: str | None, configured: str | None, source: Path, entries: Callable[[], list],
            json_output: bool = False, later: str | None = None, recorded: str | None = None) -> bool:
    """Record a finished fit in the registry (a dry run's in the dry runs' own); a registry that cannot take it
    is a warning naming how to record it later, never a loss: the calibration file is written already. Beside
    a JSON report the line goes to stderr, so stdout stays one JSON object. Whether it was recorded."""
    from alembic.util.exc import CommandError
    from sqlalchemy.exc import SQLAlchemyError

    from accelcal_rig.cli.registry_access import register

    try:
        print(register(flag, configured, entries(), recorded), file=sys.stderr if json_output else sys.stdout)
        return True
    except (RigError, SQLAlchemyError, OSError, CommandError) as exc:
        print(f"rig: warning: not recorded in the registry: {one_line(exc)} (record it later: "
              f"{later or f'rig registry add {source}'})", file=sys.stderr)
        return False


def publish_final_state(publisher: LivePublisher, output: Path, follow_up: FollowUp) -> None:
    """A complete campaign's final state, as its file and calibration say it, on its live card: a run killed
    after its last pose, or whose last update never reached the registry, shows done once resumed."""
    from accelcal_rig.fit.campaign_file import calibration_verdicts
    from accelcal_rig.store.read import load_campaign

    campaign = load_campaign(output)
    judged = (calibration_verdicts(output, follow_up.calibration)["verdicts"] or {}
              if follow_up.calibration.is_file() else {})
    publisher.finish_stored(campaign.state, len(campaign.poses), campaign.poses_planned,
                            {serial: {"verdict": str(v["verdict"]), "reasons": list(v["reasons"])}
                             for serial, v in judged.items()})


def rejected_exit(rejected: list[str], fail_on_reject: bool) -> int:
    if rejected and fail_on_reject:
        print(f"rig: {len(rejected)} DUT(s) failed their acceptance limits: {', '.join(rejected)}", file=sys.stderr)
        return EXIT_REJECTED
    return 0


def _certify_after_run(output: Path, follow_up: FollowUp) -> int:
    """The certificates at the end of a run; one that cannot be written is one line, the campaign stands."""
    try:
        certify(output, follow_up.calibration, follow_up.certificates, follow_up.operator, follow_up.pdf)
    except (RigError, OSError) as exc:
        print(f"rig: error: campaign done, but no certificates: {one_line(exc)}", file=sys.stderr)
        return 1
    return 0


def certify(campaign: Path, calibration: Path, folder: Path, operator: str, pdf: bool) -> None:
    from accelcal_rig.cli.format_campaign import certificate_line
    from accelcal_rig.report.certificate import write_certificates

    written, warnings = write_certificates(campaign, calibration, folder, operator, pdf)
    for warning in warnings:
        print(f"rig: warning: {warning}", file=sys.stderr)
    for w in written:
        print(certificate_line(w))
    if written:  # a draft until a person approves it
        print(next_step(campaign))


def next_step(campaign: Path) -> str:
    """How the drafts are approved, as commands that work as printed (USER and NAME filled in): in the registry
    the campaign's rows are in — a dry run's in the dry runs' own, where its approver must be too."""
    import shlex

    from accelcal_rig.cli.follow_up import campaign_registry_url
    from accelcal_rig.registry.location import described

    try:
        url = described(campaign_registry_url(campaign, None))
    except (RigError, OSError):
        return f"certificates are drafts until approved: rig approve {shlex.quote(str(campaign))} --as USER"
    return (f"certificates are drafts until approved: rig approve {shlex.quote(str(campaign))} --as USER, USER an "
            f"approver in registry {url} (once: rig registry user add USER --full-name NAME --role approver "
            f"--registry {shlex.quote(url)})")
