"""The dashboard's registry, held so that no request waits long on it: opened at its first use (a dashboard of
campaigns works without one) and never created; every call bounded — the connection (PostgreSQL's
connect_timeout, TCP's user timeout, a statement timeout; SQLite's busy timeout), how long a request waits for
a turn (REGISTRY_AT_ONCE calls at a time, a call keeping its turn until it ends) and how long it waits for the
answer; a registry that failed is known
to be down and answered at once (503) until a probe — one request at a time, every PROBE_S — opens it again.

Why: with a PostgreSQL registry that accepted connections and never answered, every registry request queued
for 10 s and held a worker thread; eight open pages made the front page take 89 s, static files included.
Campaign pages and static files never come here.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import anyio
import anyio.from_thread
import anyio.to_thread

from accelcal_rig.errors import RigError
from accelcal_rig.registry.database import Registry, RegistryTimeouts
from accelcal_rig.registry.location import described

T = TypeVar("T")
#: What the dashboard gives a registry: a connection within 3 s, a statement within 5 s (PostgreSQL), SQLite's
#: lock within 5 s (a reader waits only for a writer's commit).
DASHBOARD_TIMEOUTS = RegistryTimeouts(connect_s=3.0, statement_s=5.0, sqlite_busy_s=5.0)
#: Registry calls under way at once; how long a request waits for a turn, and for its call's answer.
REGISTRY_AT_ONCE = 4
TURN_WAIT_S = 1.0
ANSWER_WAIT_S = 8.0
#: After a failure, how long the registry is taken as down before a request probes it again.
PROBE_S = 2.0


class RegistryDown(RigError):
    """The registry failed and has not been found back yet: answered at once (503)."""


class RegistryReadOnly(RigError):
    """A write (a login, a decision) to a registry this dashboard could open only read-only."""


def _read_only_here(url: str) -> bool:
    """Whether an SQLite registry cannot be written here: its folder on a read-only mount (root included), or
    the file or its folder not writable by this user. (A PostgreSQL role's rights show at the first write.)"""
    if not url.startswith("sqlite:///"):
        return False
    path = Path(url.removeprefix("sqlite:///"))
    try:
        mounted_read_only = bool(os.statvfs(path.parent).f_flag & os.ST_RDONLY)
    except OSError:
        return False
    return mounted_read_only or not os.access(path, os.W_OK) or not os.access(path.parent, os.W_OK)


class RegistryGate:
    def __init__(self, url: str | None, clock: Callable[[], float] = time.monotonic,
                 timeouts: RegistryTimeouts = DASHBOARD_TIMEOUTS) -> None:
        self.url = url
        self.label = described(url) if url else "none"
        self._clock, self._timeouts = clock, timeouts
        self._registry: Registry | None = None
        self._lock = threading.Condition()  # requests are answered on several threads
        self._failed_before = False         # whether the registry is down (probed after a failure), not just unopened
        self._down_until = float("-inf")
        self._down_reason = ""
        self._probing = False
        self._turns = anyio.Semaphore(REGISTRY_AT_ONCE)
        #: Opened read-only: the registry is on a read-only mount or not writable by this user (the pages read
        #: it; logins and decisions, which write, are refused saying so).
        self.read_only = False

    def get(self) -> Registry:
        """The opened registry; else opened now (this request probes it), or RegistryDown at once while it is
        known down or another request is probing it."""
        with self._lock:
            if self.url is None:
                raise RigError("no registry: serve one with rig serve --registry URL")
            # Its first opening (or one after the registry came back) is waited for, as long as a connection
            # may take; a probe of a registry known down is not.
            self._lock.wait_for(lambda: self._registry is not None or not self._probing or self._failed_before,
                                timeout=self._timeouts.connect_s + 1.0)
            if self._registry is not None:
                return self._registry
            if self._probing or self._clock() < self._down_until:
                raise RegistryDown(self._down_reason or f"registry {self.label}: being opened: try again in a moment")
            self._probing = True
        try:
            # A view changes no schema and creates nothing: a missing or older registry is one line.
            read_only = _read_only_here(self.url)
            try:
                opened = Registry.open(self.url, upgrade=False, create=False, read_only=read_only,
                                       timeouts=self._timeouts)
            except RigError as exc:  # a full disk: it cannot be opened to write, but it can be read
                if read_only or "disk I/O error" not in str(exc):
                    raise
                read_only = True
                opened = Registry.open(self.url, upgrade=False, create=False, read_only=True, timeouts=self._timeouts)
        except Exception as exc:
            self.failed(exc)
            with self._lock:
                self._probing = False
                self._lock.notify_all()
            raise
        with self._lock:
            self._probing, self._registry, self._down_until, self._failed_before = False, opened, float("-inf"), False
            self.read_only = read_only
            self._lock.notify_all()
        return opened

    def writable(self) -> None:
        """Refuse (RegistryReadOnly) what would write to a registry opened read-only."""
        self.get()
        if self.read_only:
            raise RegistryReadOnly(f"registry {self.label} is read-only here (a read-only mount, a full disk, or not "
                                   "writable by this user): its pages are shown, but logins and decisions need a "
                                   "writable one")

    def failed(self, exc: BaseException | None = None) -> None:
        """After a registry failure: taken as down for PROBE_S (answered at once meanwhile), then probed. A
        refusal this gate made itself (down, busy) changes nothing: requests arriving faster than PROBE_S must
        not keep a registry from being probed."""
        if isinstance(exc, RegistryDown):
            return
        with self._lock:
            opened, self._registry = self._registry, None
            self._down_until, self._failed_before = self._clock() + PROBE_S, True
            reason = str(exc).splitlines()[0] if exc is not None and str(exc) else ""
            self._down_reason = (reason if reason.startswith("registry ") else
                                 f"registry {self.label}: did not answer ({reason or 'failed'})") + \
                " (tried again every few seconds)"
        if opened is not None:
            opened.engine.dispose()

    def forget(self) -> None:
        """After an unforeseen failure (perhaps not the registry's): opened again at the next request."""
        with self._lock:
            opened, self._registry = self._registry, None
        if opened is not None:
            opened.engine.dispose()

    async def call(self, work: Callable[..., T], *args: object, turn_wait_s: float = TURN_WAIT_S,
                   answer_wait_s: float = ANSWER_WAIT_S, down_if_late: bool = True) -> T:
        """`work(*args)` in a worker thread once a turn is free: RegistryDown (503) when none frees within
        `turn_wait_s`, or when the answer takes beyond `answer_wait_s` (the request stops waiting; the call
        keeps its turn until it ends, so no more than REGISTRY_AT_ONCE threads ever wait on the registry; with
        `down_if_late` the registry is then taken as down)."""
        with anyio.move_on_after(turn_wait_s) as waited:
            await self._turns.acquire()
        if waited.cancelled_caught:
            raise RegistryDown(f"registry {self.label}: busy ({REGISTRY_AT_ONCE} calls under way on it): try again "
                               "in a moment")
        claim = threading.Lock()
        state = {"started": False, "released": False}

        def release(in_worker: bool) -> None:
            with claim:
                if state["released"]:
                    return
                state["released"] = True
            if in_worker:
                anyio.from_thread.run_sync(self._turns.release)
            else:
                self._turns.release()

        def run() -> T:
            with claim:
                state["started"] = True
            try:
                return work(*args)
            finally:
                try:
                    release(in_worker=True)
                except RuntimeError:  # the server's event loop is gone: nothing waits for a turn any more
                    pass

        try:
            with anyio.move_on_after(answer_wait_s):
                return await anyio.to_thread.run_sync(run, abandon_on_cancel=True)
        finally:
            with claim:
                never_ran = not state["started"]
            if never_ran:
                release(in_worker=False)
        if down_if_late:
            self.failed(TimeoutError(f"no answer within {answer_wait_s:g} s"))
        raise RegistryDown(f"registry {self.label}: no answer within {answer_wait_s:g} s")
