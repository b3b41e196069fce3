"""Read a campaign file without the writer's help: status now, arrays for fitting later."""

from __future__ import annotations

import hashlib
import json
import os
import socket
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from accelcal_rig.errors import ConfigError
from accelcal_rig.store.campaign_file import FORMAT_NAME


def _open_checked(path: Path, mode: str, cannot_open: str, **options: Any) -> h5py.File:
    if not path.exists():
        raise ConfigError(f"{path}: no such campaign file")
    try:
        file = h5py.File(path, mode, **options)
    except OSError as exc:
        raise ConfigError(f"{path}: {cannot_open} ({exc})") from None
    if file.attrs.get("format") != FORMAT_NAME:
        file.close()
        raise ConfigError(f"{path}: not an accelcal-rig campaign file")
    return file


def open_campaign(path: Path) -> h5py.File:
    """Open read-only without taking HDF5's file lock, so a running campaign can be inspected."""
    return _open_checked(path, "r", "not a readable HDF5 file", locking=False)


def open_campaign_for_update(path: Path) -> h5py.File:
    """Open for adding results (the fit); refused while a writer holds the file (a running campaign)."""
    return _open_checked(path, "a", "cannot open for writing (is a campaign still running on it?)")


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


#: Attempts and first wait for a consistent read of a file a running campaign is writing.
SNAPSHOT_ATTEMPTS = 6
SNAPSHOT_FIRST_WAIT_S = 0.05


def campaign_status(path: Path, sleep: Callable[[float], None] | None = None) -> dict[str, Any]:
    """The campaign's state and progress, as `rig status` prints it.

    A running campaign may be mid-flush when we read (the file is not opened in SWMR mode), which shows
    as an HDF5 read error; with `sleep`, the read is retried with doubling waits (about 1.5 s in all).
    """
    if not path.exists():
        raise ConfigError(f"{path}: no such campaign file")
    for attempt in range(SNAPSHOT_ATTEMPTS if sleep else 1):
        try:
            return _read_status(path)
        except (ConfigError, OSError, KeyError, ValueError) as exc:
            last = exc
            if sleep:
                sleep(SNAPSHOT_FIRST_WAIT_S * 2**attempt)
    if isinstance(last, ConfigError):
        raise last
    raise ConfigError(f"{path}: no consistent read (a campaign is writing it?): {last}")


def _read_status(path: Path) -> dict[str, Any]:
    with open_campaign(path) as file:
        attrs = file.attrs
        plan_keys = [_text(k) for k in file["plan/step_key"][:]]
        plan_kinds = [_text(k) for k in file["plan/kind"][:]]
        done_keys = {_text(k) for k in file["poses/step_key"][:]}
        pending = [k for k, kind in zip(plan_keys, plan_kinds) if kind == "pose" and k not in done_keys]
        setpoints = list(dict.fromkeys(float(v) for v in file["plan/setpoint_c"][:]))  # plan order
        events = file["events"]
        last_event = _text(events["message"][-1]) if events["message"].shape[0] else ""
        state = _text(attrs["state"])
        return {
            "file": str(path),
            "procedure": _text(attrs.get("procedure_name", "")),
            "state": state,
            "writer": _writer_liveness(attrs) if state in ("created", "running") else None,
            "runs": int(attrs.get("runs", 1)),
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
            "integrity": "; ".join(integrity_problems(file)) or "ok",
        }


@dataclass(frozen=True)
class StoredCampaign:
    """What a resume needs to know of a campaign before touching it or the rig."""

    procedure_yaml: str
    rig_yaml: str
    plan_fingerprint: str
    procedure_path: Path
    dry_run: bool
    seed: int
    state: str
    poses_stored: int
    poses_planned: int


def read_stored_campaign(path: Path) -> StoredCampaign:
    with open_campaign(path) as file:
        attrs = file.attrs
        return StoredCampaign(
            procedure_yaml=_text(file["config/procedure_yaml"][()]),
            rig_yaml=_text(file["config/rig_yaml"][()]),
            plan_fingerprint=_text(file["plan"].attrs["fingerprint"]),
            procedure_path=Path(_text(attrs["procedure_path"])),
            dry_run=bool(attrs.get("dry_run", False)),
            seed=int(attrs.get("seed", 0)),
            state=_text(attrs["state"]),
            poses_stored=int(file["poses/step_key"].shape[0]),
            poses_planned=int(np.count_nonzero(file["plan/kind"][:] == b"pose")),
        )


def _writer_liveness(attrs: h5py.AttributeManager) -> str:
    """Whether the process writing a `running` file is still there: `alive`, `gone (resume it)`, or
    `unknown` when it ran on another host."""
    pid, host = int(attrs.get("writer_pid", 0)), _text(attrs.get("writer_host", ""))
    if not pid or host != socket.gethostname():
        return f"unknown (pid {pid} on {host or 'an unknown host'})"
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return f"gone (pid {pid} ended without closing the file: continue with rig resume)"
    except PermissionError:
        pass  # exists, owned by someone else
    return f"alive (pid {pid})"


def integrity_problems(file: h5py.File) -> list[str]:
    """What is wrong with a campaign file's poses, one line each (empty when every pose-aligned dataset
    has one row per stored pose and no pose of the plan is stored twice or is foreign to it)."""
    problems = []
    keys = [_text(k) for k in file["poses/step_key"][:]]
    n = len(keys)
    aligned = {f"poses/{name}": d for name, d in file["poses"].items()}
    for group in ("duts", "simulation_truth"):
        for serial, sub in file.get(group, {}).items():
            aligned.update({f"{group}/{serial}/{name}": d for name, d in sub.items()
                            if isinstance(d, h5py.Dataset) and d.maxshape[0] is None})
    problems += [f"{path}: {d.shape[0]} rows for {n} poses" for path, d in aligned.items() if d.shape[0] != n]
    duplicates = sorted(k for k, count in Counter(keys).items() if count > 1)
    if duplicates:
        problems.append(f"poses stored more than once: {', '.join(duplicates)}")
    planned = {_text(k) for k, kind in zip(file["plan/step_key"][:], file["plan/kind"][:]) if _text(kind) == "pose"}
    foreign = sorted(set(keys) - planned)
    if foreign:
        problems.append(f"poses not in the plan: {', '.join(foreign)}")
    return problems


def status_json(path: Path, sleep: Callable[[float], None] | None = None) -> str:
    return json.dumps(campaign_status(path, sleep))


@dataclass(frozen=True)
class DutPoses:
    """One DUT's stored poses as arrays (row i is pose i of `poses/`)."""

    serial: str
    range_g: int
    lsb_g: float
    setpoint_c: np.ndarray            # (N,)
    t_s: np.ndarray                   # (N,) clock time of each pose's first sample
    temperature_c: np.ndarray         # (N,) DUT's own sensor, mean of before and after the block
    mean_g: np.ndarray                # (N, 3)
    stderr_g: np.ndarray              # (N, 3)
    reference_g: np.ndarray           # (N, 3) expected reading from the turntable
    reference_accuracy_arcsec: float  # ± per turntable axis, from the rig config
    truth_parameters: np.ndarray | None  # (N, 12) simulation truth, dry runs only


def read_dut_poses(file: h5py.File, serial: str) -> DutPoses:
    dut = file["duts"][serial]
    truth = file.get(f"simulation_truth/{serial}/parameters")
    return DutPoses(
        serial=serial,
        range_g=int(dut.attrs["range_g"]),
        lsb_g=float(dut.attrs["lsb_g"]),
        setpoint_c=file["poses/setpoint_c"][:],
        t_s=file["poses/t_start_s"][:],
        temperature_c=dut["temperature_c"][:].mean(axis=1),
        mean_g=dut["mean_g"][:],
        stderr_g=dut["stderr_g"][:],
        reference_g=dut["gravity_reference_g"][:],
        reference_accuracy_arcsec=float(file["poses"].attrs.get("turntable_accuracy_arcsec", 0.0)),
        truth_parameters=truth[:] if truth is not None else None,
    )


def measurements_sha256(file: h5py.File) -> str:
    """Digest of the measured data (pose keys, raw codes, temperatures, references), not of the file:
    fit results written into the file later leave it unchanged."""
    digest = hashlib.sha256()
    digest.update(b"".join(k if isinstance(k, bytes) else k.encode() for k in file["poses/step_key"][:]))
    for serial in sorted(file["duts"]):
        for name in ("raw_codes", "temperature_c", "gravity_reference_g"):
            digest.update(np.ascontiguousarray(file["duts"][serial][name][:]).tobytes())
    return digest.hexdigest()


def rows_at_setpoint(path: Path, file: h5py.File, setpoint_c: float | None) -> tuple[float, np.ndarray]:
    """(setpoint, boolean rows of `poses/` there) for analyses at one temperature; `setpoint_c` None means
    the file's only setpoint, and is refused when there are several."""
    setpoints = file["poses/setpoint_c"][:]
    available = list(dict.fromkeys(setpoints.tolist()))
    listed = ", ".join(f"{s:g}" for s in available)
    if not available:
        raise ConfigError(f"{path}: no poses stored")
    if setpoint_c is None:
        if len(available) > 1:
            raise ConfigError(f"{path}: poses at {len(available)} setpoints ({listed} °C): choose one with --setpoint")
        setpoint_c = available[0]
    rows = setpoints == setpoint_c
    if not rows.any():
        raise ConfigError(f"{path}: no poses at {setpoint_c:g} °C (setpoints: {listed})")
    return float(setpoint_c), rows
