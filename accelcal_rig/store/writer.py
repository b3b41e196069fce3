"""Write a campaign: every record into its journal first (fsync'd), then the campaign file rebuilt from it.

The journal (`campaign.h5.journal`) is the durable truth and is only ever appended to. The campaign file
(`campaign.h5`, the documented HDF5 layout) is never written in place: it is rebuilt whole from what the
journal holds and swapped in by rename, at every state change and, as poses and soaks come in, at most
every `FILE_INTERVAL_S` of wall time (more rarely for large files, so rebuilding stays a small share of a
run: a dry run of 64 DUTs would otherwise spend a fifth of its time rebuilding at its soaks).
A kill at any moment leaves the journal whole up to its last acknowledged record and the file at one of
its complete versions; `rig resume` and `rig repair` rebuild the file from the journal.

One process writes a campaign: the writer holds its lock from before the first byte changes until it
closes. On a full disk the journal's reserve takes the records that stop the campaign; the file stays
at its last version until space is freed.
"""

from __future__ import annotations

import os
import socket
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from accelcal_rig import __version__
from accelcal_rig.core.signals import signals_deferred
from accelcal_rig.durable import clear_stale_temporaries, free_bytes, remove, write_atomically
from accelcal_rig.errors import ConfigError, DiskFull, InsufficientSpace
from accelcal_rig.store import lock
from accelcal_rig.store.codec import (
    encode_events,
    encode_header,
    encode_instruments,
    encode_pose,
    encode_run,
    encode_soak,
    encode_state,
    replay,
)
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.hdf5_file import DamagedFile, campaign_image
from accelcal_rig.store.journal import JournalWriter
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.records import (
    CampaignHeader,
    Event,
    PoseRecord,
    RunStart,
    SoakTrace,
    StateChange,
    StoredEvent,
    utc_now,
)
from accelcal_rig.store.repair import mend_journal
from accelcal_rig.store.space import StorageEstimate, megabytes, reserve_bytes

#: Least wall time between two rebuilds of the campaign file while poses come in.
FILE_INTERVAL_S = 2.0
#: …and at least this many times the last rebuild's own duration.
FILE_COST_FACTOR = 20.0


@dataclass(frozen=True)
class Reopened:
    """What reopening a campaign to resume it found."""

    previous_state: str        # the state the last run left: "running" or "created" means it never closed
    run: int                   # this run's number (1 was the run that created the campaign)
    poses_stored: int
    repairs: tuple[str, ...]   # what was mended or set aside, one line each
    clock_now_s: float         # where the campaign's clock resumes


class CampaignWriter:
    """Owns a campaign for the length of a run."""

    def __init__(self, path: Path, journal: JournalWriter, campaign: Campaign, storage: StorageEstimate | None) -> None:
        self.path = path
        self._journal = journal
        self._campaign = campaign
        self._storage = storage
        self._pending: list[StoredEvent] = []
        self._file_written_at = float("-inf")
        self._file_cost_s = 0.0
        self._file_behind = True
        #: Why the disk cannot take more (full, or failing; None while it can): the campaign file then stays
        #: as it is and measuring stops, the records that say so going into the journal's reserve.
        self._write_failed: str | None = None
        self._stop_raised = False
        self._closed = False

    # ------------------------------------------------------------------ opening
    @classmethod
    def create(cls, path: Path, header_fields: dict[str, Any], *, overwrite: bool,
               storage: StorageEstimate | None = None) -> CampaignWriter:
        """A new campaign at `path` (replacing one there only with `overwrite`); `header_fields`: the
        CampaignHeader's fields but its id, creation time and software version."""
        lock.acquire(path, "rig run")
        try:
            journal = journal_path(path)
            if (path.exists() or journal.exists()) and not overwrite:
                raise ConfigError(f"{path}: campaign file exists; choose another -o or pass --overwrite")
            clear_stale_temporaries(path, journal)
            header = CampaignHeader(campaign_id=uuid.uuid4().hex, created=utc_now(), software_version=__version__,
                                    **header_fields)
            campaign = Campaign(header)
            run = _run_start(1)
            campaign.runs.append(run)
            reserve = reserve_bytes(storage.pose_bytes if storage else 0)
            with signals_deferred():
                # Replacing a campaign: its campaign file goes once the new journal is on disk and before it
                # replaces the old one, so a kill leaves the old campaign (its journal alone) or the new.
                journal_writer = JournalWriter.create(journal, encode_header(header) + encode_run(run), reserve,
                                                      before_replace=lambda: remove(path, "the campaign file replaced"))
                writer = cls(path, journal_writer, campaign, storage)
                writer._write_file()
            return writer
        except BaseException:
            lock.release(path)
            raise

    @classmethod
    def reopen(cls, path: Path, storage: StorageEstimate | None = None) -> tuple[CampaignWriter, Reopened]:
        """Open an existing campaign to continue it: a record a killed run left half-written is cut off,
        a campaign file without a journal gets one, and the campaign file is rebuilt."""
        lock.acquire(path, "rig resume")
        try:
            clear_stale_temporaries(path, journal_path(path))  # what a killed run left half-built
            with signals_deferred():
                writer, repairs = cls._open_journal(path, storage)
                campaign = writer._campaign
                previous = campaign.state
                run = _run_start(campaign.run_count + 1)
                writer._append(encode_run(run))
                campaign.runs.append(run)
                writer._write_file()
            return writer, Reopened(previous, run.run, len(campaign.poses), tuple(repairs), campaign.clock_now_s())
        except BaseException:
            lock.release(path)
            raise

    @classmethod
    def _open_journal(cls, path: Path, storage: StorageEstimate | None) -> tuple[CampaignWriter, list[str]]:
        if not path.exists() and not journal_path(path).exists():
            raise ConfigError(f"{path}: no such campaign file to resume")
        repairs = mend_journal(path)
        journal_writer, found = JournalWriter.reopen(journal_path(path), reserve_bytes(storage.pose_bytes if storage else 0))
        campaign = replay(found, journal_path(path).name)
        campaign.journal_bytes = found.end
        if journal_writer.tail_kept is not None:
            repairs.append(f"{found.tail_bytes} bytes after the journal's last whole record (a record the run that died "
                           f"was writing, or a damaged one) cut off, kept as {journal_writer.tail_kept.name}")
        return cls(path, journal_writer, campaign, storage), repairs + campaign.notes

    # ------------------------------------------------------------------ what the run reads back
    @property
    def campaign(self) -> Campaign:
        """Everything stored so far (the fit stage reads the measurements from here)."""
        return self._campaign

    def stored_step_keys(self) -> set[str]:
        return set(self._campaign.stored_keys)

    # ------------------------------------------------------------------ writing
    def _append(self, record: bytes) -> None:
        """Pending events and then `record` into the journal, as one write."""
        events = encode_events(self._pending) if self._pending else b""
        self._journal.append(events + record)
        self._campaign.events.extend(self._pending)
        self._pending.clear()
        self._campaign.journal_bytes = self._journal.end
        self._file_behind = True

    def _stop_if_full(self, what: str) -> None:
        """Once the disk is full or failing (the journal into its reserve, or the campaign file could not
        be written): stop the measurements, once. What was written stays stored; the records of the stop
        still fit in the reserve."""
        if self._write_failed is None and self._journal.space_exhausted:
            self._write_failed = (f"no space left on {self.path.parent.resolve()} (the campaign journal is into its "
                                  "reserve)")
        if self._write_failed is not None and not self._stop_raised:
            self._stop_raised = True
            raise DiskFull(f"{self._write_failed}: {what} stored; measuring stops while there is room to record it")

    def append_pose(self, pose: PoseRecord) -> None:
        """Store one pose for every DUT: when this returns it is on disk (fsync'd), whole or not at all.
        Signals wait until the pose is written. DiskFull (after storing it) once the disk is full."""
        with signals_deferred():
            self._append(encode_pose(pose))
            self._campaign.add_pose(pose, "this run")
            self._write_file_when_due()
            self._stop_if_full(f"pose {pose.step_key}")

    def write_soak(self, soak: SoakTrace) -> None:
        """Store a soak's trace; DiskFull (after storing it) once the disk is full."""
        with signals_deferred():
            self._append(encode_soak(soak, list(soak.serials) or self._campaign.serials))
            self._campaign.add_soak(soak)
            self._write_file_when_due()
            self._stop_if_full(f"the soak {soak.label}")

    def record_instruments(self, instruments: dict[str, dict[str, str]]) -> None:
        """The drivers and endpoints of this run (a resumed run may reach an instrument another way)."""
        with signals_deferred():
            self._append(encode_instruments(instruments))
            self._campaign.instruments.update(instruments)

    def log_event(self, event: Event) -> None:
        """Buffer an event; it reaches the journal with the next pose, soak or state change."""
        self._pending.append(StoredEvent(event.t_s, utc_now(), event.level, event.kind, event.message))

    def set_state(self, state: str, *, reason: str = "", finished: bool = False) -> None:
        """Record a state change (a full disk does not stop this: the journal keeps its reserve for it)."""
        with signals_deferred():
            change = StateChange(state, reason, utc_now() if finished else "")
            self._append(encode_state(change))
            campaign = self._campaign
            campaign.state = state
            if state == "running":  # a resumed run starts afresh: the last run's ending no longer applies
                campaign.abort_reason, campaign.finished = "", ""
            if reason:
                campaign.abort_reason = reason
            if finished:
                campaign.finished = change.wall_time
            self._write_file()

    def flush(self) -> None:
        """Buffered events into the journal."""
        if self._pending:
            with signals_deferred():
                self._append(b"")

    def _write_file_when_due(self) -> None:
        """Rebuild the file if the last rebuild is long enough ago (else it stays behind its journal)."""
        if time.monotonic() - self._file_written_at >= max(FILE_INTERVAL_S, FILE_COST_FACTOR * self._file_cost_s):
            self._write_file()

    def _write_file(self) -> None:
        """Rebuild the campaign file from what is stored and swap it in. On a full disk the file stays at
        its last version (the journal holds everything) and measuring stops at the next pose or soak."""
        if self._write_failed is not None:
            return
        started = time.monotonic()
        try:
            write_atomically(self.path, campaign_image(self._campaign, self._journal.end), "the campaign file")
        except (DiskFull, ConfigError) as exc:  # a full or failing disk: measuring stops at the next pose
            self._write_failed = str(exc)
            return
        except DamagedFile as exc:
            self._write_failed = f"{self.path}: {exc}"
            return
        self._file_written_at = time.monotonic()
        self._file_cost_s = self._file_written_at - started
        self._file_behind = False

    def check_space(self, poses_left: int) -> None:
        """Before a setpoint: DiskFull if the disk has filled up already, InsufficientSpace when the rest of
        the campaign would not fit (so a campaign stops between setpoints rather than in one)."""
        self._stop_if_full("everything so far")
        if self._storage is None or not poses_left:
            return
        needed, free = self._storage.remaining_bytes(poses_left), free_bytes(self.path.parent)
        if free < needed:
            raise InsufficientSpace(f"not enough space left on {self.path.parent.resolve()} for the rest of the "
                                    f"campaign ({poses_left} poses): {megabytes(free)} free, about {megabytes(needed)} "
                                    "needed; free some and resume")

    def close(self) -> list[str]:
        """Flush, bring the campaign file up to date, release the campaign. Never raises: what could not be
        done is returned, one line each (the journal holds every record that was acknowledged)."""
        if self._closed:
            return []
        self._closed = True
        problems = []
        try:
            self.flush()
        except (DiskFull, ConfigError, OSError) as exc:
            problems.append(f"the last events could not be stored: {exc}")
        try:
            if self._file_behind:
                self._write_file()
        except (ConfigError, OSError) as exc:
            problems.append(f"{self.path} not brought up to date ({exc}); the journal holds everything: "
                            f"rig repair {self.path} once that is mended")
        if self._write_failed is not None and self._file_behind:
            problems.append(f"{self.path} is behind its journal ({self._write_failed}); rig resume or rig repair brings it "
                            "up to date once that is mended")
        self._journal.close()
        lock.release(self.path)
        return problems


def _run_start(run: int) -> RunStart:
    return RunStart(run, os.getpid(), socket.gethostname(), utc_now())
