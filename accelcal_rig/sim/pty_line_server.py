"""A serial device with a real path: a pseudo-terminal whose far end a simulator answers line by line.

Every simulated serial device of a process is answered by one thread (`PtyHub`), which waits on all
their pseudo-terminals at once: a fixture of 64 bridges as 64 threads would spend its time handing the
interpreter from thread to thread. A reply a fault delays is written when due, holding up no other
device (and no later reply of its own device: a device answers in order).

A client that closes the port (or another that opens it) ends its conversation, as DTR does on a USB serial
board: the rest of a reply it did not read is dropped, and so is a request it left unfinished, so the next client
reads only the replies to its own requests. The hub sees clients come and go through one inotify watch on every
device's path (sim/pty_clients.py), and takes those events before it reads any byte a client sent after them.
"""

from __future__ import annotations

import heapq
import itertools
import os
import select
import selectors
import termios
import threading
import time
import tty

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.line_answers import Handler, LineAnswers, Overlong
from accelcal_rig.sim.pty_clients import ClientWatch

#: Longest a reply waits for its client to read it.
WRITE_DEADLINE_S = 2.0


class PtyLineServer:
    """Reads requests ending in `terminator` (None: at CR, LF or CR LF, line_answers.ANY_LINE_END) from the
    pty and writes back `handle(request)` and the reply terminator (the same unless given); a line too long
    to be a request is answered by `overlong` (none: not at all), without ever being held whole; `strip` and
    `stale_after_s` as sim/line_answers.py says."""

    def __init__(self, handle: Handler, terminator: bytes | None = b"\n", name: str = "pty",
                 faults: ReplyFaults | None = None, reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", overlong: Overlong | None = None, strip: bool = True,
                 stale_after_s: float | None = None) -> None:
        self.name = name
        self._master, self._slave = os.openpty()
        tty.setraw(self._master)
        tty.setraw(self._slave)  # the slave stays open so the path keeps working between clients
        os.set_blocking(self._master, False)  # the hub serves every device: none of them may block it
        self.path = os.ttyname(self._slave)
        self._answers = LineAnswers(handle, terminator, reply_terminator, encoding, faults,
                                    defer=lambda delay_s, reply, _: _HUB.send(self, delay_s, reply), overlong=overlong,
                                    strip=strip, stale_after_s=stale_after_s)
        #: Counts the clients' comings and goings: a reply is for the session its request came in.
        self.session = 0
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
            _HUB.notice_clients(self)  # a client's coming or going counts before any byte it sent after
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

    def write(self, reply: bytes, session: int) -> None:
        """A reply written later (a delayed one) for the client of `session`, unless the device has been
        stopped, or that client has gone, since."""
        with self.lock:
            if not self.closed and session == self.session:
                self._write(reply)

    def client_changed(self) -> None:
        """A client opened or closed the port (the hub saw it)."""
        with self.lock:
            if not self.closed:
                self.client_went()

    def client_went(self) -> None:
        """The conversation so far is over (the caller holds the lock): what the port still holds of its replies
        is dropped, and so is the request it left unfinished."""
        self.session += 1
        termios.tcflush(self._slave, termios.TCIFLUSH)
        self._answers.forget_line()

    def _write(self, reply: bytes) -> None:
        """All of `reply`, waiting for room at most WRITE_DEADLINE_S: a client that stopped reading (its
        driver gave up on a long reply) loses the rest, and the hub, every other device and `stop` go on. A
        client that closes the port meanwhile loses the rest at once."""
        session = self.session
        view = memoryview(reply)
        deadline_s = time.monotonic() + WRITE_DEADLINE_S
        try:
            while view:
                try:
                    view = view[os.write(self._master, view):]
                    continue
                except BlockingIOError:  # the buffer is full: wait until it drains, or the client goes
                    pass
                left_s = deadline_s - time.monotonic()
                if left_s <= 0:
                    break
                select.select(_HUB.client_events(), [self._master], [], left_s)
                _HUB.notice_clients(self)
                if self.session != session:
                    return
        except OSError:
            return  # the client side went away: nobody to answer
        if view:
            LOGGER.warning("simulated device %s: %d bytes of a reply not read within %g s: dropped",
                           self.name, len(view), WRITE_DEADLINE_S)


#: The selector's mark for the client watch's descriptor (None marks the wake-up pipe).
_CLIENT_EVENTS = "client events"


class PtyHub:
    """One thread answering every registered pty server, started with the first and ended with the last."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._selector: selectors.BaseSelector | None = None
        self._thread: threading.Thread | None = None
        self._wake_read, self._wake_write = -1, -1
        self._servers: set[PtyLineServer] = set()
        self._clients: ClientWatch | None = None
        self._watched: dict[int, PtyLineServer] = {}  # by the client watch's number
        self._due: list[tuple[float, int, PtyLineServer, bytes, int]] = []  # delayed replies, soonest first
        self._order = itertools.count()

    def add(self, server: PtyLineServer) -> None:
        with self._lock:
            if self._thread is None:
                self._selector = selectors.DefaultSelector()
                self._wake_read, self._wake_write = os.pipe()
                self._selector.register(self._wake_read, selectors.EVENT_READ, None)
                self._clients = ClientWatch()
                if self._clients.fileno >= 0:
                    self._selector.register(self._clients.fileno, selectors.EVENT_READ, _CLIENT_EVENTS)
                self._thread = threading.Thread(target=self._serve, name="simulated-ptys", daemon=True,
                                                args=(self._selector, self._wake_read, self._wake_write,
                                                      self._clients))
                self._thread.start()
            assert self._selector is not None and self._clients is not None
            self._servers.add(server)
            self._selector.register(server.fileno, selectors.EVENT_READ, server)
            number = self._clients.watch(server.path)
            if number is not None:
                self._watched[number] = server
            os.write(self._wake_write, b"r")  # the loop waits on the new set from now on

    def remove(self, server: PtyLineServer) -> None:
        with self._lock:
            if server not in self._servers or self._selector is None:
                return
            self._servers.discard(server)
            self._selector.unregister(server.fileno)
            for number in [number for number, watched in self._watched.items() if watched is server]:
                del self._watched[number]
                if self._clients is not None:
                    self._clients.forget(number)
            last = not self._servers
            thread, wake = self._thread, self._wake_write
            if last:
                self._thread, self._clients = None, None
            os.write(wake, b"x" if last else b"r")
        if last and thread is not None:
            thread.join(5.0)

    def client_events(self) -> list[int]:
        """The descriptor to wait on for clients coming and going (none where they are not watched)."""
        clients = self._clients
        return [clients.fileno] if clients is not None and clients.fileno >= 0 else []

    def notice_clients(self, current: PtyLineServer | None = None) -> None:
        """Tell each device whose port a client opened or closed since the last look (from the hub's thread;
        `current` is a device whose lock the caller already holds)."""
        clients = self._clients
        if clients is None:
            return
        for number in clients.changed():
            with self._lock:
                server = self._watched.get(number)
            if server is None:
                continue
            if server is current:
                server.client_went()
            else:
                server.client_changed()

    def send(self, server: PtyLineServer, delay_s: float, reply: bytes) -> None:
        """Write `reply` now, or once `delay_s` has passed, after any reply of the device still due (and only if
        its client is still there then)."""
        now = time.monotonic()
        due = max(now + delay_s, server.due_s)
        server.due_s = due
        if due <= now:
            server._write(reply)  # from within its answer: the hub holds its lock
            return
        heapq.heappush(self._due, (due, next(self._order), server, reply, server.session))

    def _serve(self, selector: selectors.BaseSelector, wake_read: int, wake_write: int, clients: ClientWatch) -> None:
        """The loop of one run of the hub (its selector, wake-up pipe and client watch are its own: a hub started
        again after its last server went has new ones)."""
        while True:
            timeout = max(0.0, self._due[0][0] - time.monotonic()) if self._due else None
            for key, _ in selector.select(timeout):
                if key.data is None:
                    if b"x" in os.read(wake_read, 64):
                        selector.close()
                        clients.close()
                        for fd in (wake_read, wake_write):
                            os.close(fd)
                        return
                    continue
                if key.data is _CLIENT_EVENTS:
                    self.notice_clients()
                    continue
                server: PtyLineServer = key.data
                if server in self._servers and not server.received():
                    self._forget(server, selector)
            while self._due and self._due[0][0] <= time.monotonic():
                _, _, server, reply, session = heapq.heappop(self._due)
                if server in self._servers:
                    server.write(reply, session)

    def _forget(self, server: PtyLineServer, selector: selectors.BaseSelector) -> None:
        """A pty that failed to read: no longer waited on."""
        with self._lock:
            if server in self._servers:
                self._servers.discard(server)
                selector.unregister(server.fileno)


_HUB = PtyHub()
