"""A serial device with a real path: a pseudo-terminal whose far end a simulator answers line by line."""

from __future__ import annotations

import os
import select
import threading
import tty

from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.line_answers import Handler, LineAnswers


class PtyLineServer:
    """Reads requests ending in `terminator` from the pty and writes back `handle(request)` and the reply
    terminator (the same unless given)."""

    def __init__(self, handle: Handler, terminator: bytes = b"\n", name: str = "pty",
                 faults: ReplyFaults | None = None, reply_terminator: bytes | None = None,
                 encoding: str = "utf-8") -> None:
        self._answers = LineAnswers(handle, terminator, reply_terminator, encoding, faults)
        self._master, self._slave = os.openpty()
        tty.setraw(self._master)
        tty.setraw(self._slave)  # the slave stays open so the path keeps working between clients
        self.path = os.ttyname(self._slave)
        self._wake_read, self._wake_write = os.pipe()  # stop() writes here: the thread wakes at once
        self._thread = threading.Thread(target=self._serve, name=name, daemon=True)

    def start(self) -> PtyLineServer:
        self._thread.start()
        return self

    def stop(self) -> None:
        os.write(self._wake_write, b"x")
        self._thread.join(5.0)
        for fd in (self._master, self._slave, self._wake_read, self._wake_write):
            os.close(fd)

    def _serve(self) -> None:
        while True:
            readable, _, _ = select.select([self._master, self._wake_read], [], [])
            if self._wake_read in readable:
                return
            try:
                data = os.read(self._master, 65536)
            except OSError:
                return
            self._answers.feed(data, lambda reply: os.write(self._master, reply))
