"""Read a campaign file without the writer's help: status now, arrays for fitting later."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import h5py

from accelcal_rig.errors import ConfigError
from accelcal_rig.store.campaign_file import FORMAT_NAME


def open_campaign(path: Path) -> h5py.File:
    """Open read-only without taking HDF5's file lock, so a running campaign can be inspected."""
    if not path.exists():
        raise ConfigError(f"{path}: no such campaign file")
    try:
        file = h5py.File(path, "r", locking=False)
    except OSError as exc:
        raise ConfigError(f"{path}: not a readable HDF5 file ({exc})") from None
    if file.attrs.get("format") != FORMAT_NAME:
        file.close()
        raise ConfigError(f"{path}: not an accelcal-rig campaign file")
    return file


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def campaign_status(path: Path) -> dict[str, Any]:
    """The campaign's state and progress, as `rig status` prints it."""
    with open_campaign(path) as file:
        attrs = file.attrs
        plan_keys = [_text(k) for k in file["plan/step_key"][:]]
        plan_kinds = [_text(k) for k in file["plan/kind"][:]]
        done_keys = {_text(k) for k in file["poses/step_key"][:]}
        pending = [k for k, kind in zip(plan_keys, plan_kinds) if kind == "pose" and k not in done_keys]
        setpoints = list(dict.fromkeys(float(v) for v in file["plan/setpoint_c"][:]))  # plan order
        events = file["events"]
        last_event = _text(events["message"][-1]) if events["message"].shape[0] else ""
        return {
            "file": str(path),
            "procedure": _text(attrs.get("procedure_name", "")),
            "state": _text(attrs["state"]),
            "poses_done": int(file["poses/step_key"].shape[0]),
            "poses_total": plan_kinds.count("pose"),
            "next_step": pending[0] if pending else None,
            "samples_per_pose": int(attrs["samples_per_pose"]),
            "duts": list(file["duts"].keys()),
            "setpoints_c": setpoints,
            "dry_run": bool(attrs.get("dry_run", False)),
            "started": _text(attrs["started"]),
            "finished": _text(attrs["finished"]) or None,
            "abort_reason": _text(attrs["abort_reason"]) or None,
            "last_event": last_event,
        }


def status_json(path: Path) -> str:
    return json.dumps(campaign_status(path))
