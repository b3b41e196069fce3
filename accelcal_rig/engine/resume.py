"""Continuing a campaign from its file: only with the procedure and rig it was started with.

Connection details (ports, addresses, timeouts) may change between runs — a USB adapter that comes back
as another device is still the same rig — everything that shapes the measurement may not.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from accelcal_rig.config.load import LoadedConfig, swap_chamber_profile
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.config.yaml_lines import KeyPath, parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.plan.compile import Plan
from accelcal_rig.store.content import Campaign

#: Rig keys that say how to reach an instrument (or how to retry it, what faults a simulator injects, whom
#: to notify), not what it is or how it measures.
CONNECTION_KEYS = frozenset({"endpoint", "timeout_s", "baudrate", "parity", "stopbits", "spi_speed_hz", "retry",
                             "faults", "notify"})
#: Procedure keys that name files rather than shape the campaign.
PROCEDURE_FILE_KEYS = frozenset({"rig"})


@dataclass(frozen=True)
class ResumePoint:
    """Where a resumed run starts: the poses already stored, and whether the last run died."""

    done_keys: frozenset[str]
    unclean: bool        # the last run never closed the file: the rig may be anywhere
    run: int


def check_same_campaign(path: Path, stored: Campaign, procedure: LoadedConfig[Procedure],
                        rig: LoadedConfig[RigConfig], plan: Plan, dry_run: bool) -> None:
    """Refuse to resume with a procedure or rig that differs from the campaign's, naming the first key."""
    stored_dry_run = bool(stored.attrs.get("dry_run", False))
    if stored_dry_run != dry_run:
        started = "a dry run" if stored_dry_run else "on the real rig"
        raise ConfigError(f"{path}: the campaign was started {started}; resume it the same way "
                          f"({'with' if stored_dry_run else 'without'} --dry-run)")
    checks: list[tuple[str, LoadedConfig[Any], str, Any, frozenset[str]]] = [
        ("procedure", procedure, stored.header.procedure_yaml, Procedure, PROCEDURE_FILE_KEYS),
        ("rig", rig, stored.header.rig_yaml, RigConfig, CONNECTION_KEYS)]
    for kind, new, old_text, model, ignored in checks:
        try:
            old = model.model_validate(parse_yaml_text(old_text, f"{path}: its stored {kind}"))
            if kind == "rig" and stored.attrs.get("chamber_profile"):  # the dry run's swapped-in chamber
                old = swap_chamber_profile(old, str(stored.attrs["chamber_profile"]))
        except (ValidationError, ConfigError) as exc:
            raise ConfigError(f"{path}: the campaign's stored {kind} no longer validates: "
                              f"{str(exc).splitlines()[0]}") from None
        difference = first_difference(old.model_dump(mode="json"), new.model.model_dump(mode="json"), ignored)
        if difference is not None:
            key, before, after = difference
            raise new.error(key, f"is {after!r} but the campaign in {path} was started with {before!r}; "
                                 f"resume with the same {kind} (or start a new campaign)")
    if plan.fingerprint != stored.header.plan.fingerprint:
        raise ConfigError(f"{path}: the plan compiled now differs from the campaign's (fingerprint "
                          f"{plan.fingerprint[:12]} vs {stored.header.plan.fingerprint[:12]}): start a new campaign")


def first_difference(old: Any, new: Any, ignored: frozenset[str], key: KeyPath = ()) -> tuple[KeyPath, Any, Any] | None:
    """The first key path where two plain (JSON-like) values differ, skipping keys named in `ignored`."""
    if isinstance(old, dict) and isinstance(new, dict):
        for name in list(old) + [k for k in new if k not in old]:
            if name in ignored:
                continue
            found = first_difference(old.get(name), new.get(name), ignored, key + (name,))
            if found is not None:
                return found
        return None
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        for index, (a, b) in enumerate(zip(old, new)):
            found = first_difference(a, b, ignored, key + (index,))
            if found is not None:
                return found
        return None
    return None if old == new else (key, old, new)
