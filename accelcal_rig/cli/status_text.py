"""`rig status` as a person reads it: what the campaign is doing, how far it is, what is left, and what to
do next — from the same dictionary `rig status --json` prints."""

from __future__ import annotations

from typing import Any

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.fit.early_check import Finding


def status_lines(status: dict[str, Any]) -> list[str]:
    """The lines of a campaign's status, in the order an operator asks: which, what now, how far, then."""
    progress = status.get("progress") or {}
    state = status["state"]
    lines = [f"campaign   {status['file']} ({status['procedure']}{', dry run' if status.get('dry_run') else ''})"]
    lines.append(f"state      {_state(status)}")
    if progress and state in ("created", "running"):
        lines.append(f"now        {progress.get('line', '')}")
    lines.append(f"poses      {status['poses_done']} of {status['poses_total']}"
                 + (f", next {status['next_step']}" if status.get("next_step") else ", all stored"))
    setpoints = status.get("setpoints_c") or []
    if setpoints:
        lines.append(f"setpoints  {len(setpoints)}: " + ", ".join(f"{t:g}" for t in setpoints) + " °C")
    lines.append(f"DUTs       {', '.join(status.get('duts') or []) or 'none'}"
                 f" ({status['samples_per_pose']} samples per pose)")
    lines.append(f"started    {_time(status['started'])}" + (f", run {status['runs']}" if status.get("runs", 1) > 1 else ""))
    if status.get("finished"):
        lines.append(f"finished   {_time(status['finished'])}")
    if status.get("abort_reason"):
        lines.append(f"stopped    {status['abort_reason']}")
    if status.get("last_event"):
        lines.append(f"last event {status['last_event']}")
    if status.get("integrity") and status["integrity"] != "ok":
        lines.append(f"integrity  {status['integrity']}")
    if status.get("campaign_file") and status["campaign_file"] != "current":
        lines.append(f"file       {status['campaign_file']}")
    if status.get("calibration"):
        lines.append(f"fit        {status['calibration']}")
    for part in status.get("follow_up") or []:
        if part["state"] != "not due" and not (part["part"] == "calibration" and part["state"] == "done"):
            lines.append(f"{part['part']:<10} {part['state']}: {part['detail']}")
    for flagged in status.get("early_check") or []:
        lines.append(f"flagged    {early_finding(flagged)}")
    for serial, judged in (status.get("verdicts") or {}).items():
        reasons = f": {'; '.join(judged['reasons'])}" if judged["verdict"] in ("FAIL", "CONDITIONAL") else ""
        lines.append(f"verdict    {serial} {judged['verdict'] or 'not judged'}{reasons}")
    hint = _next_step(status)
    if hint:
        lines.append(f"next       {hint}")
    return lines


def early_finding(flagged: dict[str, Any]) -> str:
    """One finding of the early check as its event says it, without the `DUT ` it begins with."""
    return Finding(**flagged).message().removeprefix("DUT ")


def _state(status: dict[str, Any]) -> str:
    state = status["state"]
    if state in ("created", "running"):
        return f"{state}, writer {status.get('writer') or 'unknown'}"
    return state


def _next_step(status: dict[str, Any]) -> str:
    """What to do about it: continue a campaign that stopped, or finish what a complete one lacks."""
    state, writer = status["state"], status.get("writer") or ""
    if state == "aborted" or (state in ("created", "running") and writer.startswith("gone")):
        return f"rig resume {status['file']}  (continues with the poses not stored)"
    unfinished = [p["part"] for p in status.get("follow_up") or [] if p["state"] in ("missing", "stale", "unknown")]
    if state == "done" and unfinished:
        return f"rig resume {status['file']}  (writes what is missing: {', '.join(unfinished)})"
    return ""


def _time(iso: str) -> str:
    """`2026-12-01T16:46:29+00:00` → `2026-12-01 16:46:29 UTC`."""
    return iso.replace("T", " ").replace("+00:00", " UTC")


def watch_header(status: dict[str, Any], interval_s: float) -> str:
    remaining = (status.get("progress") or {}).get("remaining_s")
    left = f", about {format_duration(remaining)} left" if remaining is not None else ""
    return f"every {interval_s:g} s (Ctrl-C to stop){left}"


def watch_text(status: dict[str, Any], interval_s: float, clear: bool) -> str:
    """One screen of `rig status --watch`: the status (the terminal cleared first if `clear`), then how often
    it is shown again."""
    return ("\x1b[H\x1b[2J" if clear else "") + "\n".join(status_lines(status)) + f"\n({watch_header(status, interval_s)})"
