"""A simulated line device's side of the conversation, whatever carries it (a pty, a TCP connection):
requests cut at their terminator, answered one by one, each answer spoiled by any transient fault drawn."""

from __future__ import annotations

import time
from collections.abc import Callable

from accelcal_rig.sim.faults import ReplyFaults

#: A device's handler: the request line (stripped) → the reply without its terminator, or None (no reply).
Handler = Callable[[str], str | None]


#: Writes a reply after a delay (s) without holding up other devices: a server that answers many devices
#: from one thread; None: the answering thread sleeps (it answers this device alone).
Deferral = Callable[[float, bytes, Callable[[bytes], object]], None]


class LineAnswers:
    def __init__(self, handle: Handler, request_terminator: bytes = b"\n", reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", faults: ReplyFaults | None = None, defer: Deferral | None = None) -> None:
        self._handle = handle
        self._request_terminator = request_terminator
        self._reply_terminator = request_terminator if reply_terminator is None else reply_terminator
        self._encoding = encoding
        self._faults = faults
        self._defer = defer
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
        if fault == "corrupt":
            reply = self._faults.corrupt(reply)  # type: ignore[union-attr]
        delay_s = self._faults.faults.delay_s if fault == "delay" else 0.0  # type: ignore[union-attr]
        if self._defer is not None:
            self._defer(delay_s, reply, write)
            return
        if delay_s:
            time.sleep(delay_s)
        write(reply)
