"""A serial device with a real path: a pseudo-terminal whose far end a simulator answers line by line.

Every simulated serial device of a process is answered by one thread (`PtyHub`), which waits on all
their pseudo-terminals at once: a fixture of 64 bridges as 64 threads would spend its time handing the
interpreter from thread to thread. A reply a fault delays is written when due, holding up no other
device (and no later reply of its own device: a device answers in order).
"""

from __future__ import annotations

import heapq
import itertools
import os
import selectors
import threading
import time
import tty

from accelcal_rig.core.descriptors import write_within
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.line_answers import Handler, LineAnswers, Overlong

#: Longest a reply waits for its client to read it.
WRITE_DEADLINE_S = 2.0


class PtyLineServer:
    """Reads requests ending in `terminator` from the pty and writes back `handle(request)` and the reply
    terminator (the same unless given); a line too long to be a request is answered by `overlong` (none:
    not at all), without ever being held whole (sim/line_answers.py)."""

    def __init__(self, handle: Handler, terminator: bytes = b"\n", name: str = "pty",
                 faults: ReplyFaults | None = None, reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", overlong: Overlong | None = None) -> None:
        self.name = name
        self._master, self._slave = os.openpty()
        tty.setraw(self._master)
        tty.setraw(self._slave)  # the slave stays open so the path keeps working between clients
        os.set_blocking(self._master, False)  # the hub serves every device: none of them may block it
        self.path = os.ttyname(self._slave)
        self._answers = LineAnswers(handle, terminator, reply_terminator, encoding, faults,
                                    defer=lambda delay_s, reply, _: _HUB.send(self, delay_s, reply), overlong=overlong)
        #: When this device's latest reply is due: a later one is never written before it.
        self.due_s = 0.0
        #: Held by the hub while it reads, answers or writes, and by `stop` while it closes: a descriptor is
        #: never used once closed (its number may already be another file's).
        self.lock = threading.Lock()
        self.closed = False

    def start(self) -> PtyLineServer:
        _HUB.add(self)
        return self

    def stop(self) -> None:
        _HUB.remove(self)
        with self.lock:
            self.closed = True
            for fd in (self._master, self._slave):
                os.close(fd)

    @property
    def fileno(self) -> int:
        return self._master

    @property
    def buffered_bytes(self) -> int:
        """Bytes held of the line not yet ended (bounded)."""
        return self._answers.buffered_bytes

    @property
    def peak_buffered_bytes(self) -> int:
        """The most bytes ever held of an unended line, for tests."""
        return self._answers.peak_buffered_bytes

    def received(self) -> bool:
        """Answer what has arrived; False once the pty is gone. A simulator that fails on a request is
        logged and answers nothing: the other devices of the hub go on."""
        with self.lock:
            if self.closed:
                return False
            try:
                data = os.read(self._master, 65536)
            except BlockingIOError:  # readiness without data: nothing to answer yet
                return True
            except OSError:
                return False
            try:
                self._answers.feed(data, self._write)
            except Exception:  # noqa: BLE001 - one simulator's fault must not silence every device
                LOGGER.exception("simulated device %s: request failed", self.name)
            return True

    def write(self, reply: bytes) -> None:
        """A reply written later (a delayed one), unless the device has been stopped since."""
        with self.lock:
            if not self.closed:
                self._write(reply)

    def _write(self, reply: bytes) -> None:
        """All of `reply`, waiting for room at most WRITE_DEADLINE_S: a client that stopped reading (its
        driver gave up on a long reply) loses the rest, and the hub, every other device and `stop` go on."""
        try:
            left = write_within(self._master, reply, time.monotonic() + WRITE_DEADLINE_S)
        except OSError:
            return  # the client side went away: nobody to answer
        if left:
            LOGGER.warning("simulated device %s: %d bytes of a reply not read within %g s: dropped",
                           self.name, left, WRITE_DEADLINE_S)


class PtyHub:
    """One thread answering every registered pty server, started with the first and ended with the last."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._selector: selectors.BaseSelector | None = None
        self._thread: threading.Thread | None = None
        self._wake_read, self._wake_write = -1, -1
        self._servers: set[PtyLineServer] = set()
        self._due: list[tuple[float, int, PtyLineServer, bytes]] = []  # delayed replies, soonest first
        self._order = itertools.count()

    def add(self, server: PtyLineServer) -> None:
        with self._lock:
            if self._thread is None:
                self._selector = selectors.DefaultSelector()
                self._wake_read, self._wake_write = os.pipe()
                self._selector.register(self._wake_read, selectors.EVENT_READ, None)
                self._thread = threading.Thread(target=self._serve, name="simulated-ptys", daemon=True,
                                                args=(self._selector, self._wake_read, self._wake_write))
                self._thread.start()
            assert self._selector is not None
            self._servers.add(server)
            self._selector.register(server.fileno, selectors.EVENT_READ, server)
            os.write(self._wake_write, b"r")  # the loop waits on the new set from now on

    def remove(self, server: PtyLineServer) -> None:
        with self._lock:
            if server not in self._servers or self._selector is None:
                return
            self._servers.discard(server)
            self._selector.unregister(server.fileno)
            last = not self._servers
            thread, wake = self._thread, self._wake_write
            if last:
                self._thread = None
            os.write(wake, b"x" if last else b"r")
        if last and thread is not None:
            thread.join(5.0)

    def send(self, server: PtyLineServer, delay_s: float, reply: bytes) -> None:
        """Write `reply` now, or once `delay_s` has passed, after any reply of the device still due."""
        now = time.monotonic()
        due = max(now + delay_s, server.due_s)
        server.due_s = due
        if due <= now:
            server._write(reply)  # from within its answer: the hub holds its lock
            return
        heapq.heappush(self._due, (due, next(self._order), server, reply))

    def _serve(self, selector: selectors.BaseSelector, wake_read: int, wake_write: int) -> None:
        """The loop of one run of the hub (its selector and wake-up pipe are its own: a hub started again
        after its last server went has new ones)."""
        while True:
            timeout = max(0.0, self._due[0][0] - time.monotonic()) if self._due else None
            for key, _ in selector.select(timeout):
                if key.data is None:
                    if b"x" in os.read(wake_read, 64):
                        selector.close()
                        for fd in (wake_read, wake_write):
                            os.close(fd)
                        return
                    continue
                server: PtyLineServer = key.data
                if server in self._servers and not server.received():
                    self._forget(server, selector)
            while self._due and self._due[0][0] <= time.monotonic():
                _, _, server, reply = heapq.heappop(self._due)
                if server in self._servers:
                    server.write(reply)

    def _forget(self, server: PtyLineServer, selector: selectors.BaseSelector) -> None:
        """A pty that failed to read: no longer waited on."""
        with self._lock:
            if server in self._servers:
                self._servers.discard(server)
                selector.unregister(server.fileno)


_HUB = PtyHub()
