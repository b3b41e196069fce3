"""A simulated line device's side of the conversation, whatever carries it (a pty, a TCP connection):
requests cut at their terminator, answered one by one, each answer spoiled by any transient fault drawn."""

from __future__ import annotations

import time
from collections.abc import Callable

from accelcal_rig.sim.faults import ReplyFaults

#: A device's handler: the request line (stripped) → the reply without its terminator, or None (no reply).
Handler = Callable[[str], str | None]


class LineAnswers:
    def __init__(self, handle: Handler, request_terminator: bytes = b"\n", reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", faults: ReplyFaults | None = None) -> None:
        self._handle = handle
        self._request_terminator = request_terminator
        self._reply_terminator = request_terminator if reply_terminator is None else reply_terminator
        self._encoding = encoding
        self._faults = faults
        self._pending = b""

    def feed(self, data: bytes, write: Callable[[bytes], object]) -> None:
        """Take received bytes; answer each complete request through `write`."""
        self._pending += data
        while self._request_terminator in self._pending:
            line, self._pending = self._pending.split(self._request_terminator, 1)
            reply = self._handle(line.decode(self._encoding, errors="replace").strip())
            if reply is not None:
                self._send(reply.encode(self._encoding, errors="replace") + self._reply_terminator, write)

    def _send(self, reply: bytes, write: Callable[[bytes], object]) -> None:
        fault = self._faults.draw(("drop", "delay", "corrupt", "disconnect")) if self._faults else None
        if fault == "drop":
            return
        if fault == "delay":
            time.sleep(self._faults.faults.delay_s)  # type: ignore[union-attr]
        elif fault == "corrupt":
            reply = self._faults.corrupt(reply)  # type: ignore[union-attr]
        write(reply)
