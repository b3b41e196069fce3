"""A running campaign's live status, published to the registry database on a thread of its own.

The campaign hands it each progress snapshot and each event (returning at once: it only keeps the latest);
the thread writes what changed at most every `interval_s` of wall time, and at least every `heartbeat_s`
even when nothing did, so that a dashboard can tell a quiet rig from a dead one. A database that cannot be
reached is one warning and a retry (with a growing pause, at most RETRY_MAX_S); the events of the outage are
kept (the newest EVENTS_WAITING) and published when it is back. Nothing here can slow, stop or fail the
campaign: its file is the truth, this is a view of it."""

from __future__ import annotations

import logging
import os
import socket
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.engine.progress import Progress
from accelcal_rig.registry.live import LiveBoard, LiveEvent, campaign_key
from accelcal_rig.registry.location import described

#: Shortest wall time between two writes of a campaign's snapshot.
INTERVAL_S = 2.0
#: Longest wall time without a write (the rig's heartbeat: STALE_AFTER_S must exceed it with room).
HEARTBEAT_S = 10.0
#: Longest pause between two tries to reach a database that went away.
RETRY_MAX_S = 30.0
#: Campaign time between two published temperature points (a 14-hour campaign: about 840).
TEMPERATURE_EVERY_S = 60.0
#: Events kept while the database cannot be reached.
EVENTS_WAITING = 2000
#: Event kinds that are findings on a DUT (shown on its rig's card).
FINDING_KINDS = frozenset({"early_check"})


@dataclass(frozen=True)
class Identity:
    """Who publishes: the rig, its computer, the campaign file and what runs in it."""

    rig: str
    campaign: Path
    procedure: str
    dry_run: bool
    host: str = field(default_factory=socket.gethostname)
    pid: int = field(default_factory=os.getpid)

    @property
    def key(self) -> str:
        return campaign_key(self.host, str(self.campaign))


class LivePublisher:
    """A progress listener and an event sink that publish to `url`'s live tables. `fresh`: a new campaign in
    the file (an earlier one's published events are dropped); a resumed one continues its row."""

    def __init__(self, url: str, identity: Identity, fresh: bool, interval_s: float = INTERVAL_S,
                 heartbeat_s: float = HEARTBEAT_S, connect: Any = None) -> None:
        self.url, self.identity, self.fresh = url, identity, fresh
        self.interval_s, self.heartbeat_s = interval_s, heartbeat_s
        self._connect = connect or _open_board
        self._lock = threading.Condition()
        self._row: dict[str, Any] = _first_row(identity)
        self._changed = False
        self._started = False      # nothing is published before the campaign's first progress
        self.finished = False      # the campaign's last word was given
        self._events: deque[LiveEvent] = deque(maxlen=EVENTS_WAITING)
        self._temperatures: list[tuple[float, float | None, float | None]] = []
        self._last_point_s = float("-inf")
        self._closing = False
        self.published = 0          # writes that reached the database
        self.failures = 0           # writes that did not
        self._thread = threading.Thread(target=self._serve, name="live-status", daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ what the campaign hands it
    @property
    def started(self) -> bool:
        """Whether the campaign gave its first progress (before it, there is nothing of it to publish)."""
        return self._started

    def __call__(self, progress: Progress) -> None:
        with self._lock:
            self._started = True
            self._row.update(
                state="running", phase=progress.phase[:32], setpoint_c=progress.setpoint_c,
                setpoint_number=progress.setpoint_number, setpoints_total=progress.setpoints_total,
                poses_done=progress.poses_done, poses_total=progress.poses_total, chamber_c=progress.chamber_c,
                dut_c=list(progress.dut_c), remaining_s=progress.remaining_s, clock_s=progress.clock_s,
                line=progress.line())
            if progress.chamber_c is not None and progress.clock_s - self._last_point_s >= TEMPERATURE_EVERY_S:
                self._last_point_s = progress.clock_s
                mean = sum(progress.dut_c) / len(progress.dut_c) if progress.dut_c else None
                self._temperatures.append((progress.clock_s, progress.chamber_c, mean))
            self._changed = True
            self._lock.notify()

    def event(self, clock_s: float, level: str, kind: str, message: str) -> None:
        with self._lock:
            self._events.append(LiveEvent(clock_s, datetime.now(UTC).replace(tzinfo=None), level, kind, message))
            if level == "warning":
                self._row["warnings"] += 1
            elif level == "error":
                self._row["errors"] += 1
            if kind in FINDING_KINDS and level in ("warning", "error"):  # a check's summary is not a finding
                self._row["findings"] = [*self._row["findings"], message]
            self._changed = True
            self._lock.notify()

    def finish(self, state: str, poses_done: int | None = None, verdicts: dict[str, Any] | None = None,
               abort_reason: str = "") -> None:
        """The campaign's last word: how it ended and, once judged, each DUT's verdict. A run whose campaign
        never started (no progress) publishes nothing."""
        with self._lock:
            if not self._started:
                return
            self.finished = True
            self._row.update(state=state[:16], remaining_s=None, abort_reason=abort_reason,
                             phase="done" if state == "done" else state[:32])
            if poses_done is not None:
                self._row["poses_done"] = poses_done
            if verdicts:
                self._row["verdicts"] = verdicts
            self._row["line"] = _ended_line(self._row)
            self._changed = True
            self._lock.notify()

    def finish_stored(self, state: str, poses_done: int, poses_total: int, verdicts: dict[str, Any]) -> None:
        """The last word of a campaign found complete in its file (a resume with nothing left to run): published
        though this run gave no progress, so that a card its last run left "running" ends as the file says."""
        with self._lock:
            self._started = True
            self._row.update(poses_total=poses_total)
        self.finish(state, poses_done, verdicts)

    def close(self, timeout_s: float = 10.0) -> str | None:
        """Publish what is left, within `timeout_s`; what could not be, in one line (None: all of it was)."""
        with self._lock:
            self._closing = True
            self._lock.notify()
        self._thread.join(timeout_s)
        if self._started and (self._thread.is_alive() or self._changed):
            return (f"live status: the campaign's last state did not reach registry {described(self.url)} (its "
                    "campaign file has it)")
        return None

    def handler(self) -> logging.Handler:
        """A log handler passing the campaign's events (engine/events.py marks them) to this publisher."""
        return _EventHandler(self)

    # ------------------------------------------------------------------ the thread
    def _serve(self) -> None:
        board: LiveBoard | None = None
        begun, pause_s, retry_at, last_write, down_since = False, 0.0, 0.0, float("-inf"), None
        while True:
            with self._lock:
                closing = self._wait_until_due(last_write, retry_at)
                if not self._started:
                    return  # closed before the campaign started: nothing of it to publish
                row, events, temperatures = dict(self._row), list(self._events), list(self._temperatures)
                self._changed = False
            try:
                if board is None:
                    board = self._connect(self.url)
                if not begun:
                    board.begin(self.identity.key, row, self.fresh)
                    begun = True
                board.publish(self.identity.key, row, events, temperatures)
            except Exception as exc:  # noqa: BLE001 - a view: whatever the database says, the campaign goes on
                self.failures += 1
                with self._lock:
                    self._changed = True  # the snapshot, the events and the points are all still to publish
                if down_since is None:
                    down_since = time.monotonic()
                    LOGGER.warning("live status not published: %s; the campaign goes on, retrying", _why(exc, self.url))
                if closing:
                    return
                board, pause_s = None, min(RETRY_MAX_S, max(1.0, pause_s * 2))  # opened again at the next try
                retry_at = time.monotonic() + pause_s
                continue
            self.published += 1
            last_write, pause_s = time.monotonic(), 0.0
            with self._lock:  # what was published is dropped; what came since stays
                for _ in range(min(len(events), len(self._events))):
                    self._events.popleft()
                del self._temperatures[:len(temperatures)]
                if closing and not self._changed:
                    return
            if down_since is not None:
                LOGGER.info("live status: registry %s takes it again after %.0f s", described(self.url),
                            time.monotonic() - down_since)
                down_since = None

    def _wait_until_due(self, last_write: float, retry_at: float) -> bool:
        """Under the lock: wait until a write is due (a change `interval_s` after the last write, a heartbeat,
        the end, or the retry after a failure); whether the publisher is closing."""
        while not self._closing:
            now = time.monotonic()
            if now < retry_at:
                self._lock.wait(retry_at - now)
                continue
            if not self._started:
                self._lock.wait()  # not begun: nothing to say until the campaign's first progress
                continue
            due_at = last_write + (self.interval_s if self._changed else self.heartbeat_s)
            if now >= due_at:
                return False
            self._lock.wait(due_at - now)
        return True


class _EventHandler(logging.Handler):
    def __init__(self, publisher: LivePublisher) -> None:
        super().__init__(logging.INFO)
        self.publisher = publisher

    def emit(self, record: logging.LogRecord) -> None:
        kind = getattr(record, "event_kind", None)
        if kind is not None:
            self.publisher.event(float(getattr(record, "clock_s", 0.0)), record.levelname.lower(), str(kind),
                                 str(getattr(record, "event_message", record.getMessage())))


def _open_board(url: str) -> LiveBoard:
    from accelcal_rig.registry.database import Registry

    return LiveBoard(Registry.open(url))


def _first_row(identity: Identity) -> dict[str, Any]:
    return {"rig": identity.rig[:128], "host": identity.host[:255], "campaign": str(identity.campaign)[:4096],
            "procedure": identity.procedure[:128], "dry_run": identity.dry_run, "pid": identity.pid,
            "state": "running", "phase": "starting", "setpoint_c": None, "setpoint_number": 0, "setpoints_total": 0,
            "poses_done": 0, "poses_total": 0, "chamber_c": None, "dut_c": [], "remaining_s": None, "clock_s": 0.0,
            "line": "starting", "warnings": 0, "errors": 0, "verdicts": {}, "findings": [], "abort_reason": "",
            "started_at": datetime.now(UTC).replace(tzinfo=None)}


def _ended_line(row: dict[str, Any]) -> str:
    text = f"{row['state']} · poses {row['poses_done']}/{row['poses_total']}"
    return f"{text} · {row['abort_reason']}" if row["abort_reason"] else text


def _why(error: Exception, url: str) -> str:
    """The failure in one line naming the registry once."""
    text = (str(getattr(error, "orig", None) or error).strip().splitlines() or [type(error).__name__])[0]
    return text if text.startswith("registry ") else f"registry {described(url)}: {text}"
