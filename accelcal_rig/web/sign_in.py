"""The dashboard's sign-in: password hashes checked off the event loop, a few at a time; failed logins limited
per client (here, in memory) and per account (in the registry, registry/sign_ins.py: the lockout every dashboard
and the command line see); sessions that end when their user's generation is raised, after an idle time and
after an absolute lifetime.

Why each: an argon2id check takes tens of milliseconds of a core and 64 MiB by design; run where requests are
answered, forty wrong logins froze every page, static files included. A name no user has is limited here as a
user's is, so the answers say nothing of which names exist.
"""

from __future__ import annotations

import asyncio
import os
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from datetime import datetime
from typing import Any, TypeVar

from accelcal_rig.registry.approvals import utc_now_naive
from accelcal_rig.registry.sign_ins import ACCOUNT_FAILURES, LOCKOUT_S

T = TypeVar("T")
#: Password checks under way at once (one per core of a small server), and how many may wait for one before
#: a login is answered "busy" at once.
HASHING_AT_ONCE = 2
HASHING_WAITING = 32
#: The password checks' niceness (0 normal, 19 lowest): below the threads that answer pages.
HASHING_NICENESS = 10
#: Failed logins from one client within CLIENT_WINDOW_S before its logins are refused until the oldest expires.
CLIENT_FAILURES = 10
CLIENT_WINDOW_S = 10 * 60
#: Clients and unknown names remembered at most (the oldest forgotten first): a flood of made-up addresses
#: cannot grow the server's memory without end.
REMEMBERED = 10_000
#: A session ends after this long without a request, and this long after its login whatever happens.
IDLE_S = 30 * 60
ABSOLUTE_S = 8 * 3600


class Busy(Exception):
    """Too many password checks are waiting: answered at once, to be tried again."""


class Hashing:
    """Password checks on threads of their own, HASHING_AT_ONCE at a time, at a lower CPU priority (nice
    HASHING_NICENESS, which the check's own lane threads inherit): the event loop never runs one, and a flood of
    them leaves the cores to the pages. (argon2id's default check is ~0.2 s of both cores of a small server.)"""

    def __init__(self) -> None:
        self._pool = ThreadPoolExecutor(HASHING_AT_ONCE, thread_name_prefix="password-check",
                                        initializer=_lower_priority)
        self._pending = 0

    async def run(self, check: Callable[[], T]) -> T:
        if self._pending >= HASHING_AT_ONCE + HASHING_WAITING:
            raise Busy()
        self._pending += 1
        try:
            return await asyncio.wrap_future(self._pool.submit(check))
        finally:
            self._pending -= 1


def _lower_priority() -> None:
    """This thread (and the threads it starts) at niceness HASHING_NICENESS, where the system allows it."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), HASHING_NICENESS)
    except (AttributeError, OSError):  # not Linux, or not allowed: the checks still run off the event loop
        pass


class FailureWindows:
    """Failures per key (a client's address, an unknown name) in a sliding window, bounded in keys."""

    def __init__(self, limit: int, window_s: float, clock: Callable[[], float]) -> None:
        self.limit, self.window_s, self._clock = limit, window_s, clock
        self._failures: OrderedDict[str, deque[float]] = OrderedDict()

    def retry_after_s(self, key: str) -> float:
        """How long until `key` may try again (0: now)."""
        times = self._recent(key)
        return max(0.0, times[0] + self.window_s - self._clock()) if len(times) >= self.limit else 0.0

    def failed(self, key: str) -> float:
        """One failure of `key`; how long it must now wait (0: not yet at its limit)."""
        times = self._recent(key)
        times.append(self._clock())
        self._failures[key] = times
        self._failures.move_to_end(key)
        while len(self._failures) > REMEMBERED:
            self._failures.popitem(last=False)
        return self.retry_after_s(key)

    def forget(self, key: str) -> None:
        self._failures.pop(key, None)

    def _recent(self, key: str) -> deque[float]:
        times = self._failures.get(key, deque())
        horizon = self._clock() - self.window_s
        while times and times[0] <= horizon:
            times.popleft()
        return times


@dataclass
class SignInLimits:
    """What limits logins on one dashboard: failures per client, and per name no user has (a user's own are the
    registry's), and the password checks' threads."""

    clients: FailureWindows
    unknown_names: FailureWindows
    hashing: Hashing

    @classmethod
    def create(cls, clock: Callable[[], float] = time.monotonic) -> SignInLimits:
        return cls(FailureWindows(CLIENT_FAILURES, CLIENT_WINDOW_S, clock),
                   FailureWindows(ACCOUNT_FAILURES, LOCKOUT_S, clock), Hashing())


@dataclass(frozen=True)
class SessionPolicy:
    """How long a session lives: without a request, and at all. `clock`: wall seconds (sessions outlive no
    restart, but a session's times are compared across requests)."""

    idle_s: float = IDLE_S
    absolute_s: float = ABSOLUTE_S
    clock: Callable[[], float] = time.time

    def alive(self, since_s: Any, seen_s: Any) -> bool:
        now = self.clock()
        return (isinstance(since_s, (int, float)) and isinstance(seen_s, (int, float))
                and now - since_s <= self.absolute_s and now - seen_s <= self.idle_s)


@dataclass
class SignInPolicy:
    """Everything that decides a dashboard's sign-ins, in one place (tests give it clocks of their own):
    sessions' lifetimes, the limits on logins, and the registry's time (naive UTC) of lockouts and the record."""

    sessions: SessionPolicy = field(default_factory=SessionPolicy)
    limits: SignInLimits = field(default_factory=SignInLimits.create)
    utc_now: Callable[[], datetime] = utc_now_naive
