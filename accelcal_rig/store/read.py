"""Read a campaign without the writer's help, whatever state its files are in: status now, arrays for
fitting later. Never changes a byte of what it reads.

A campaign is read from its journal when it has one (the durable truth, always up to the last pose
stored, also while a run is writing it) and from its HDF5 file otherwise. Anything that is not a
readable campaign is one ConfigError naming the file and what is wrong with it.
"""

from __future__ import annotations

import json
import os
import re
import socket
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2, site_gravity_g
from accelcal_rig.durable import stale_temporaries
from accelcal_rig.errors import ConfigError
from accelcal_rig.store import lock
from accelcal_rig.store.codec import NotACampaignJournal, replay
from accelcal_rig.store.content import Campaign, take_what_the_file_kept
from accelcal_rig.store.hdf5_file import DamagedFile, read_campaign_file
from accelcal_rig.store.journal import read_journal
from accelcal_rig.store.paths import journal_path, progress_path
from accelcal_rig.store.records import STATIC_KINDS


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def load_campaign(path: Path) -> Campaign:
    """The campaign stored as `path` (its journal, else the HDF5 file itself)."""
    if path.is_dir():
        raise ConfigError(f"{path}: is a folder, not a campaign file")
    if path.exists() and not path.is_file():
        raise ConfigError(f"{path}: not a regular file")
    journal = journal_path(path)
    fallback_note = ""
    if journal.is_file():
        identity = file_identity(path)  # before the journal: see file_kept_more
        try:
            found = read_journal(journal)
        except OSError as exc:
            raise ConfigError(f"{journal}: cannot read: {exc.strerror}") from None
        try:
            campaign = replay(found, journal.name)
        except NotACampaignJournal as exc:
            if not path.is_file():
                raise ConfigError(f"{path}: no campaign: {exc}") from None
            fallback_note = f"{exc}: read from {path.name} instead"
        else:
            campaign.journal_bytes = found.end
            if found.tail_bytes and lock.holder(path) is None:  # while a run writes, its next record is on its way
                campaign.notes.append(f"{journal.name}: {found.tail_bytes} bytes after its last whole record (a record "
                                      "a run that died was writing, or a damaged one): resume or repair sets them aside")
            from_file = file_kept_more(path, identity, campaign)
            if from_file is not None:
                take_what_the_file_kept(campaign, from_file, journal.name, path.name)
            return campaign
    if not path.exists():
        if stale_temporaries(journal) or stale_temporaries(path):
            raise ConfigError(f"{path}: no campaign: a run stopped before it had created it (nothing was measured); "
                              "start it again with rig run")
        raise ConfigError(f"{path}: no such campaign file")
    campaign = read_hdf5_campaign(path)
    if fallback_note:
        campaign.notes.append(fallback_note)
    return campaign


@dataclass(frozen=True)
class FileIdentity:
    """What an HDF5 campaign file says of itself, read cheaply (attributes and pose keys only)."""

    campaign_id: str
    step_keys: frozenset[str]
    journal_bytes: int


def file_identity(path: Path) -> FileIdentity | None:
    """None when the file cannot say (missing, unreadable, or written before campaigns had ids)."""
    try:
        if not path.is_file():
            return None
        with h5py.File(path, "r", locking=False) as file:
            identity = str(file.attrs.get("campaign_id", ""))
            keys = file.get("poses/step_key")
            if not identity or not isinstance(keys, h5py.Dataset) or keys.ndim != 1 or keys.shape[0] > 10**6:
                return None
            return FileIdentity(identity, frozenset(k.decode(errors="replace") if isinstance(k, bytes) else str(k)
                                                    for k in keys[()]), int(file.attrs.get("journal_bytes", 0)))
    except (OSError, ValueError, TypeError, KeyError, OverflowError):
        return None


def check_same_campaign_files(path: Path, identity: FileIdentity | None, campaign: Campaign) -> None:
    """ConfigError when the campaign file and the journal are different campaigns."""
    if identity is not None and identity.campaign_id != campaign.header.campaign_id:
        raise ConfigError(f"{path}: it and its journal hold different campaigns ({identity.campaign_id[:12]} and "
                          f"{campaign.header.campaign_id[:12]}): move the one that does not belong away; nothing "
                          "was changed")


def file_kept_more(path: Path, identity: FileIdentity | None, campaign: Campaign) -> Campaign | None:
    """The campaign file read whole when it holds poses the journal has lost, else None. `identity` must
    be read before the journal: the journal only grows, so a pose the file had then and the journal
    lacks now is lost, not merely newer."""
    check_same_campaign_files(path, identity, campaign)
    if identity is None or identity.step_keys <= campaign.stored_keys:
        return None
    try:
        from_file = read_hdf5_campaign(path)
    except ConfigError:
        return None
    return None if from_file.damage else from_file


def read_hdf5_campaign(path: Path) -> Campaign:
    """The campaign in the HDF5 file alone (no journal consulted)."""
    if not path.is_file():
        raise ConfigError(f"{path}: not a regular file")
    try:
        file = h5py.File(path, "r", locking=False)
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: not a readable HDF5 file ({_first_line(exc)})") from None
    try:
        with file:
            campaign = read_campaign_file(file)
    except DamagedFile as exc:
        raise ConfigError(f"{path}: {str(exc).splitlines()[0]}") from None
    except (OSError, KeyError, ValueError, TypeError, IndexError, RuntimeError, AttributeError) as exc:
        raise ConfigError(f"{path}: damaged campaign file ({_first_line(exc)})") from None
    campaign.source = "file"
    return campaign


def file_currency(path: Path, campaign: Campaign, writing: bool) -> str:
    """Whether the HDF5 file holds what the journal holds (readers outside accelcal-rig see the file)."""
    if campaign.source == "file":
        return "the only copy (no journal)"
    rebuild = "a campaign is writing: it catches up as it goes" if writing else f"rig repair {path} rebuilds it"
    if not path.exists():
        return f"missing ({rebuild})"
    identity = file_identity(path)
    if identity is None:
        return f"unreadable or not a campaign file of this version ({rebuild})"
    if identity.campaign_id != campaign.header.campaign_id:
        return f"holds another campaign ({rebuild})"
    if not identity.step_keys <= {p.step_key for p in campaign.poses}:
        return f"holds poses its journal lost ({rebuild})"
    if identity.journal_bytes != campaign.journal_bytes or len(identity.step_keys) != len(campaign.poses):
        return f"behind the journal: {len(identity.step_keys)} of {len(campaign.poses)} poses ({rebuild})"
    return "current"


def writer_liveness(path: Path, campaign: Campaign) -> tuple[bool, str]:
    """(alive, description) of the process that writes a `created` or `running` campaign."""
    holder = lock.holder(path)
    if holder is not None:
        return True, f"alive ({holder})"
    run = campaign.runs[-1] if campaign.runs else None
    if campaign.source == "file" and run is not None and run.pid and run.host == socket.gethostname():
        try:  # a file from before the lock: ask the process itself
            os.kill(run.pid, 0)
            return True, f"alive (pid {run.pid})"
        except ProcessLookupError:
            pass
        except PermissionError:
            return True, f"alive (pid {run.pid})"
    last = f"pid {run.pid} on {run.host}" if run is not None and run.pid else "its last run"
    return False, f"gone ({last} ended without closing it: continue with rig resume)"


def campaign_status(path: Path, campaign: Campaign | None = None) -> dict[str, Any]:
    """The campaign's state and progress, as `rig status` prints it (`campaign`: read already)."""
    campaign = campaign if campaign is not None else load_campaign(path)
    header, state = campaign.header, campaign.state
    plan = header.plan
    alive, liveness = writer_liveness(path, campaign) if state in ("created", "running") else (False, None)
    pending = [k for k in plan.pose_keys if k not in campaign.stored_keys]
    return {
        "file": str(path),
        "procedure": str(campaign.attrs.get("procedure_name", "")),
        "state": state,
        "writer": liveness,
        "runs": campaign.run_count,
        "poses_done": len(campaign.poses),
        "poses_total": campaign.poses_planned,
        "next_step": pending[0] if pending else None,
        "samples_per_pose": campaign.samples_per_pose,
        "duts": campaign.serials,
        "setpoints_c": list(dict.fromkeys(float(v) for v in plan.setpoint_c)),
        "dry_run": bool(campaign.attrs.get("dry_run", False)),
        "started": header.created,
        "finished": campaign.finished or None,
        "abort_reason": campaign.abort_reason or None,
        "last_event": campaign.events[-1].message if campaign.events else "",
        "integrity": "; ".join(campaign.integrity_problems()) or "ok",
        "campaign_file": file_currency(path, campaign, alive),
        "progress": with_stored_count(read_progress(path), len(campaign.poses)) if alive else None,
    }


def read_progress(path: Path) -> dict[str, Any] | None:
    """The running campaign's latest snapshot (engine/progress_file.py), or None when there is none whole."""
    try:
        snapshot = json.loads(progress_path(path).read_text())
    except (OSError, ValueError):
        return None
    return snapshot if isinstance(snapshot, dict) else None


#: The pose count among a progress line's parts (engine/progress.py Progress.line joins them with " · ").
_POSE_COUNT = re.compile(r"pose \d+/\d+")
_PARTS = " · "


def with_stored_count(snapshot: dict[str, Any] | None, poses_stored: int) -> dict[str, Any] | None:
    """The snapshot counting the poses the campaign stores: it is written at most every half second (a dry
    run stores many poses between two) and may be older than the journal, whose poses are the truth."""
    if snapshot is None:
        return None
    parts = [f"pose {poses_stored}/{snapshot.get('poses_total', '?')}" if _POSE_COUNT.fullmatch(part) else part
             for part in str(snapshot.get("line", "")).split(_PARTS)]
    return {**snapshot, "poses_done": poses_stored, "line": _PARTS.join(parts)}


def without_pose_count(line: str) -> str:
    """A progress line without its pose count, for a view that shows the stored count beside it."""
    return _PARTS.join(part for part in line.split(_PARTS) if not _POSE_COUNT.fullmatch(part))


def usable_campaign(path: Path) -> Campaign:
    """The campaign, refused in one line when its measurements are damaged (fit and analyses need them)."""
    campaign = load_campaign(path)
    problems = campaign.unusable_reasons()
    if problems:
        repair = " (rig repair rebuilds it from its journal)" if campaign.source == "journal" else ""
        raise ConfigError(f"{path}: damaged measurements: {problems[0]}{repair}")
    return campaign


@dataclass(frozen=True)
class VectorPoses:
    """One DUT's stored poses of one three-axis channel as arrays (row i is pose i of `poses/`), in the channel's
    unit: its means, their standard errors and what it should have read (its reference), beside the pose's
    setpoint, time and the DUT's own temperature. `magnitude` is the size of every reference (the site's
    gravity in standard g for an accelerometer), stated by the channel's model."""

    serial: str
    channel: str
    unit: str
    range: float
    lsb: float
    setpoint_c: np.ndarray            # (N,)
    t_s: np.ndarray                   # (N,) clock time of each pose's first sample
    temperature_c: np.ndarray         # (N,) DUT's own sensor, mean of before and after the block
    mean: np.ndarray                  # (N, 3)
    stderr: np.ndarray                # (N, 3)
    reference: np.ndarray             # (N, 3) what it should have read, from the turntable's pose
    reference_accuracy_arcsec: float  # ± per turntable axis, from the rig config
    truth_parameters: np.ndarray | None  # (N, P) simulation truth, dry runs only
    verification: np.ndarray          # (N,) bool: a verification pose (the fit never sees it)
    rows: np.ndarray                  # (N,) each pose's row among the campaign's stored poses
    magnitude: float = 1.0            # the size of every reference, in the channel's unit
    truth_reference: np.ndarray | None = None  # (N, 3) the simulation's true reference, dry runs that store it
    magnitude_u: float = 0.0          # the magnitude's standard uncertainty, in the channel's unit
    approach: np.ndarray | None = None  # (N,) +1 warming, −1 cooling towards each pose (fit.hysteresis)
    rate_c_per_min: np.ndarray | None = None  # (N,) each pose's rate of temperature change (fit.hysteresis)
    #: (S, N) each pose's hysteresis state for each span the joint fit tries (fit.hysteresis; fit/approach.py)
    hysteresis_states: np.ndarray | None = None

    def subset(self, rows: np.ndarray) -> VectorPoses:
        """These poses only (a boolean mask or indices)."""
        def taken(value: np.ndarray | None) -> np.ndarray | None:
            return None if value is None else value[rows]

        return replace(self, setpoint_c=self.setpoint_c[rows], t_s=self.t_s[rows], temperature_c=self.temperature_c[rows],
                       mean=self.mean[rows], stderr=self.stderr[rows], reference=self.reference[rows],
                       verification=self.verification[rows], rows=self.rows[rows],
                       truth_parameters=taken(self.truth_parameters), truth_reference=taken(self.truth_reference),
                       approach=taken(self.approach), rate_c_per_min=taken(self.rate_c_per_min),
                       hysteresis_states=None if self.hysteresis_states is None else self.hysteresis_states[:, rows])


def dut_description(campaign: Campaign, serial: str) -> dict[str, Any]:
    return campaign.header.duts[campaign.serials.index(serial)]


def read_vector_poses(campaign: Campaign, serial: str, channel: str) -> VectorPoses:
    """One three-axis channel of the DUT over its poses taken at rest, the table standing (a rate step's turning
    table and a noise record's blocks are not a static pose); its magnitude 1 until its model states it."""
    info = campaign.channel_info(serial, channel)
    keys = campaign.pose_column("step_key")
    static = np.isin(keys, list(campaign.header.plan.keys_of(*STATIC_KINDS))) if len(keys) else np.zeros(0, bool)
    poses = VectorPoses(
        serial=serial, channel=channel, unit=info.unit, range=info.range, lsb=info.lsb,
        setpoint_c=campaign.pose_column("setpoint_c"),
        t_s=campaign.pose_column("t_start_s"),
        temperature_c=campaign.dut_column(serial, "temperature_c").mean(axis=1),
        mean=campaign.channel_column(serial, channel, "mean"),
        stderr=campaign.channel_column(serial, channel, "stderr"),
        reference=campaign.channel_column(serial, channel, "reference"),
        reference_accuracy_arcsec=float(campaign.header.turntable_accuracy_arcsec),
        truth_parameters=None,
        verification=np.isin(keys, list(campaign.header.plan.verification_keys)),
        rows=np.arange(len(keys)),
    )
    return poses if static.all() else poses.subset(static)


def described_truth(campaign: Campaign, serial: str, channel: str) -> np.ndarray | None:
    """A dry run's true parameters (N, P) of one of a DUT's channels at each stored pose's true temperature, from
    the simulation's description of it (`<channel>_polynomial_coefficients`: cubics in (T − t_ref_c) /
    half_range_c); None where the campaign has none."""
    described = campaign.header.truth.get(serial, {})
    temperature = campaign.truth_column(serial, "temperature_c")
    key = f"{channel}_polynomial_coefficients"
    if key not in described or temperature is None:
        return None
    coefficients = np.asarray(described[key], dtype=float)
    x = (temperature - float(described["t_ref_c"])) / float(described["half_range_c"])
    return np.moveaxis(np.polynomial.polynomial.polyval(x, coefficients.T), 0, -1)


def site_gravity(campaign: Campaign) -> tuple[float, float]:
    """The site's gravity and its standard uncertainty, in standard g, as the campaign recorded them."""
    return (site_gravity_g(float(campaign.attrs.get("gravity_m_s2", STANDARD_GRAVITY_M_S2))),
            site_gravity_g(float(campaign.attrs.get("gravity_uncertainty_m_s2", 0.0))))


def rows_at_setpoint(path: Path, campaign: Campaign, setpoint_c: float | None) -> tuple[float, np.ndarray]:
    """(setpoint, boolean rows of the stored poses there) for analyses at one temperature; `setpoint_c`
    None means the campaign's only setpoint, and is refused when there are several."""
    setpoints = campaign.pose_column("setpoint_c")
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
