"""The one clock shared by the engine, the soak detector, the simulators and sample timestamps.

In a lab it is real time; in a dry run it is virtual. Nothing else calls time.sleep.

The virtual clock advances only when someone sleeps on it, so a fourteen-hour campaign costs only the
requests made during it.
"""

from __future__ import annotations

import threading
import time
from typing import Protocol


class Clock(Protocol):
    kind: str

    def now(self) -> float:
        """Seconds since the clock started."""

    def sleep(self, seconds: float) -> None:
        """Let `seconds` pass."""


class RealClock:
    kind = "real"

    def __init__(self) -> None:
        self._start = time.monotonic()

    def now(self) -> float:
        return time.monotonic() - self._start

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)


class VirtualClock:
    """Time that jumps forward on `sleep`; thread-safe so simulators in other threads can read it."""

    kind = "virtual"

    def __init__(self, start_s: float = 0.0) -> None:
        self._now = float(start_s)
        self._lock = threading.Lock()

    def now(self) -> float:
        with self._lock:
            return self._now

    def sleep(self, seconds: float) -> None:
        if seconds < 0:
            raise ValueError(f"cannot sleep a negative time ({seconds} s)")
        with self._lock:
            self._now += seconds
