"""Which registry a command reads or records in, and what it records of a campaign or a recording: shared by
the registry's commands and the approval's (which sit above this, not beside each other)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from accelcal_rig.fit.calibration import CalibrationFile


def open_registry(args: argparse.Namespace, upgrade: bool = False):  # noqa: ANN201 - imported late (SQLAlchemy)
    """The registry the command names: --registry, else the rig config's (--config), else the environment's,
    else the default file. Only a recording command (`upgrade`) creates one or migrates an older schema; the
    others read it read-only (a registry on a read-only mount included)."""
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import registry_url

    return Registry.open(registry_url(args.registry, from_config(args)), upgrade=upgrade, create=upgrade,
                         read_only=not upgrade)


def from_config(args: argparse.Namespace) -> str | None:
    """The `registry:` of the rig config `--config` names, if it does."""
    if getattr(args, "config", None) is None:
        return None
    from accelcal_rig.config.load import load_rig
    from accelcal_rig.registry.location import configured

    rig = load_rig(args.config)
    return configured(rig.model.registry, rig.path)


def register(flag: str | None, configured: str | None, entries: list[dict[str, Any]],
             recorded: str | None = None) -> str:
    """Record entries in the registry they belong to: the one `--registry` (`flag`) names, else the one the
    campaign's run recorded in (`recorded`), else a dry run's in the dry runs' own and a real one's in the rig
    config's (`configured`) or the lab's; one line saying what happened (for `rig run`/`rig fit`/
    `rig fit-recording`)."""
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import described, recording_url

    simulated = any(entry["simulated"] for entry in entries)
    url = recording_url(flag or recorded, configured, simulated)
    added, already = Registry.open(url, upgrade=True).add(entries)
    tail = f", {already} registered already" if already else ""
    apart = " (a dry run: kept apart from the lab's registry)" if simulated and flag is None else ""
    return (f"registry   {len(added)} calibration{'s' if len(added) != 1 else ''} recorded in {described(url)}"
            f"{tail}{apart}")


def campaign_entries(campaign: Path, calibration: Path | None) -> list[dict[str, Any]]:
    """What the registry records of a fitted campaign (read when it is recorded)."""
    from accelcal_rig.registry.entries import campaign_entries as entries

    return entries(campaign, calibration)


def recording_entries(recording: Path, calibration: CalibrationFile, part: str,
                      simulated: bool = False) -> list[dict[str, Any]]:
    """What the registry records of a hand-held recording's fit (`simulated`: of a dry run's campaign file)."""
    from accelcal_rig.registry.entries import recording_entries as entries

    return entries(recording, calibration, part, simulated)


def rig_registry(value: str | None, rig_path: Path) -> str | None:
    """A rig config's `registry:` (relative to the config's folder)."""
    from accelcal_rig.registry.location import configured

    return configured(value, rig_path)


def stored_rig_registry(campaign: Path) -> str | None:
    """The `registry:` of the rig config a campaign was run with (as it stored it)."""
    from accelcal_rig.registry.location import campaign_rig_registry

    return campaign_rig_registry(campaign)
