"""The files of one campaign, all beside the campaign file the user names (`campaign.h5`)."""

from __future__ import annotations

from pathlib import Path


def journal_path(campaign: Path) -> Path:
    """`campaign.h5.journal`: the append-only record of everything measured, the durable truth."""
    return campaign.with_name(campaign.name + ".journal")


def lock_path(campaign: Path) -> Path:
    """`campaign.h5.lock`: held by the one process writing the campaign."""
    return campaign.with_name(campaign.name + ".lock")


def log_path(campaign: Path) -> Path:
    """`campaign.h5.log`: every line the runs printed, appended run after run."""
    return campaign.with_name(campaign.name + ".log")


def progress_path(campaign: Path) -> Path:
    """`campaign.h5.progress.json`: the running campaign's latest snapshot, for watchers (rig status, rig serve)."""
    return campaign.with_name(campaign.name + ".progress.json")
