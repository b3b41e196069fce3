"""A serial device with a real path: a pseudo-terminal whose far end a simulator answers line by line."""

from __future__ import annotations

import os
import select
import threading
import time
import tty
from collections.abc import Callable

from accelcal_rig.sim.faults import ReplyFaults


class PtyLineServer:
    """Reads requests ending in `terminator` from the pty and writes back `handle(request) + terminator`."""

    def __init__(self, handle: Callable[[str], str], terminator: bytes = b"\n", name: str = "pty",
                 faults: ReplyFaults | None = None) -> None:
        self._handle = handle
        self._faults = faults
        self._terminator = terminator
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
        pending = b""
        while True:
            readable, _, _ = select.select([self._master, self._wake_read], [], [])
            if self._wake_read in readable:
                return
            try:
                pending += os.read(self._master, 65536)
            except OSError:
                return
            while self._terminator in pending:
                line, pending = pending.split(self._terminator, 1)
                reply = self._handle(line.decode(errors="replace").strip()).encode() + self._terminator
                self._send(reply)

    def _send(self, reply: bytes) -> None:
        fault = self._faults.draw(("drop", "delay", "corrupt", "disconnect")) if self._faults else None
        if fault == "drop":
            return
        if fault == "delay":
            time.sleep(self._faults.faults.delay_s)  # type: ignore[union-attr]
        elif fault == "corrupt":
            reply = self._faults.corrupt(reply)  # type: ignore[union-attr]
        os.write(self._master, reply)
