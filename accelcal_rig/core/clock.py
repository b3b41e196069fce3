"""The one clock shared by the engine, the soak detector, the simulators and sample timestamps.

In a lab it is real time; in a dry run it is virtual. Nothing else calls time.sleep.

The virtual clock advances only when someone sleeps on it, so a fourteen-hour campaign costs only the
requests made during it.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Protocol, TypeVar

T = TypeVar("T")


class Clock(Protocol):
    kind: str

    def now(self) -> float:
        """Seconds since the clock started."""

    def sleep(self, seconds: float) -> None:
        """Let `seconds` pass."""

    def run_concurrently(self, tasks: list[Callable[[], T]]) -> list[T]:
        """Run the tasks in threads at the same time; return their results in order, or raise the first
        task's error after every task has ended (no thread is left using an instrument)."""


class RealClock:
    kind = "real"

    def __init__(self, start_s: float = 0.0) -> None:
        """`start_s`: the clock's reading now (a resumed campaign continues its time line)."""
        self._origin = time.monotonic() - start_s

    def now(self) -> float:
        return time.monotonic() - self._origin

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)

    def run_concurrently(self, tasks: list[Callable[[], T]]) -> list[T]:
        return _run_in_threads(tasks, on_start=lambda: None, on_end=lambda: None)


class VirtualClock:
    """Time that jumps forward on `sleep`; thread-safe so simulators in other threads can read it.

    Inside `run_concurrently` it is a discrete-event clock: a task's sleep waits until every task is
    sleeping (or done), then time jumps to the earliest wake-up and wakes exactly the tasks due then. So
    four sensors read "at the same time" spend the virtual time of one, as they would on a real rig.
    """

    kind = "virtual"

    def __init__(self, start_s: float = 0.0) -> None:
        self._now = float(start_s)
        self._cond = threading.Condition()
        self._awake: set[int] = set()           # participating threads not sleeping
        self._sleeping: dict[int, float] = {}   # participating thread → wake-up time

    def now(self) -> float:
        with self._cond:
            return self._now

    def sleep(self, seconds: float) -> None:
        if seconds < 0:
            raise ValueError(f"cannot sleep a negative time ({seconds} s)")
        me = threading.get_ident()
        with self._cond:
            if me not in self._awake:
                self._now += seconds
                return
            self._awake.discard(me)
            self._sleeping[me] = self._now + seconds
            self._advance()
            while me in self._sleeping:
                self._cond.wait()

    def run_concurrently(self, tasks: list[Callable[[], T]]) -> list[T]:
        def start() -> None:
            with self._cond:
                self._awake.add(threading.get_ident())

        def end() -> None:
            with self._cond:
                self._awake.discard(threading.get_ident())
                self._advance()

        return _run_in_threads(tasks, on_start=start, on_end=end)

    def _advance(self) -> None:
        """With every participant asleep, jump to the earliest wake-up; wake the ones due (lock held)."""
        if self._awake or not self._sleeping:
            return
        self._now = max(self._now, min(self._sleeping.values()))
        for thread, wake in list(self._sleeping.items()):
            if wake <= self._now:
                del self._sleeping[thread]
                self._awake.add(thread)
        self._cond.notify_all()


def _run_in_threads(tasks: list[Callable[[], T]], on_start: Callable[[], None],
                    on_end: Callable[[], None]) -> list[T]:
    results: list[T | None] = [None] * len(tasks)
    errors: list[BaseException | None] = [None] * len(tasks)
    registered = threading.Barrier(len(tasks) + 1)

    def work(index: int) -> None:
        on_start()
        try:
            registered.wait()  # every task counts as awake before any may sleep
            results[index] = tasks[index]()
        except BaseException as exc:  # noqa: BLE001 - handed to the caller below
            errors[index] = exc
        finally:
            on_end()

    threads = [threading.Thread(target=work, args=(i,), daemon=True) for i in range(len(tasks))]
    for thread in threads:
        thread.start()
    try:
        registered.wait()
        for thread in threads:
            thread.join()
    except BaseException:
        registered.abort()  # interrupted before the start: tasks not yet begun never begin
        for thread in threads:  # and none is left using an instrument when the caller goes on
            thread.join()
        raise
    for error in errors:
        if error is not None:
            raise error
    return results  # type: ignore[return-value]
