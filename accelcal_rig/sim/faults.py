"""Transient faults on a simulated instrument's replies: dropped, delayed, corrupted, a dead line.

Each simulator draws from its own random stream (seeded from the fault seed and the instrument's name),
so a fault run is repeatable. A delay is wall-clock time (it acts on the wire, whose timeouts are real); a
dead line lasts campaign time, the clock the engine's retry backoff runs on.
"""

from __future__ import annotations

import hashlib
import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from accelcal_rig.config.rig import FaultInjection

#: Bytes a noisy line produces that no reply of ours contains (replies are printable ASCII).
_JUNK = bytes([0x00, 0x7F, 0xFF, 0x1B])


class ReplyFaults:
    """Decides, reply by reply, whether and how to spoil it."""

    def __init__(self, faults: FaultInjection, name: str, now: Callable[[], float]) -> None:
        """`now`: the campaign clock's time in seconds."""
        self.faults = faults
        self._now = now
        digest = hashlib.sha256(f"{faults.seed}:{name}".encode()).digest()
        self._rng = np.random.default_rng(int.from_bytes(digest[:8], "little"))
        self._dead_until = 0.0
        self._lock = threading.Lock()
        #: How many replies each kind of fault spoiled (for tests and benchmarks).
        self.counts: dict[str, int] = {}

    def draw(self, allowed: tuple[str, ...]) -> str | None:
        """The fault for the next reply (None: answer normally)."""
        with self._lock:
            if self._now() < self._dead_until:
                return "drop"
            kinds = [k for k in self.faults.kinds if k in allowed]
            if not kinds or self._rng.random() >= self.faults.rate:
                return None
            kind = str(kinds[int(self._rng.integers(len(kinds)))])
            self.counts[kind] = self.counts.get(kind, 0) + 1
            if kind == "disconnect":
                self._dead_until = self._now() + self.faults.disconnect_s
                return "drop"
            return kind

    def corrupt(self, reply: bytes) -> bytes:
        """The reply with one byte replaced by line noise (the terminator is left alone)."""
        with self._lock:
            position = int(self._rng.integers(max(1, len(reply) - 1)))
            junk = _JUNK[int(self._rng.integers(len(_JUNK)))]
        return reply[:position] + bytes([junk]) + reply[position + 1:]


@dataclass(frozen=True)
class InstrumentFaults:
    """What one simulated instrument is told to get wrong: its replies' transient faults (None: none) and
    the rig's persistent ones, with the time they start in seconds of campaign time."""

    replies: ReplyFaults | None
    settings: FaultInjection

    @staticmethod
    def after_s(minutes: float | None) -> float | None:
        return None if minutes is None else minutes * 60.0
