"""A simulated line device's side of the conversation, whatever carries it (a pty, a TCP connection):
requests cut at their terminator, answered one by one, each answer spoiled by any transient fault drawn.

A line is bounded: a client that sends bytes and never a terminator (a wrong terminator setting, a binary
stream, a hostile peer) must not grow the simulator's memory without end. A line longer than
MAX_LINE_BYTES is discarded as it arrives (only its first bytes, for the answer, and the last few, for a
terminator split between reads, are kept) and answered, once its terminator comes, as the device answers a
request it does not know (`overlong`; none: silence); the next line is served as usual.

A device may also drop the start of a line left without its terminator for a while (`stale_after_s`: a client
that went away mid-request, noise from plugging in), and may take its lines as they came (`strip=False`: a
device whose protocol says what a space or a control byte at either end means). A device that reads any line
end (`ANY_LINE_END`) ends a request at CR, LF or CR LF, whichever comes: a client's odd terminator is answered
on its own, never joined to the next request.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable

from accelcal_rig.sim.faults import ReplyFaults

#: A device's handler: the request line (stripped) → the reply without its terminator, or None (no reply).
Handler = Callable[[str], str | None]

#: What a device answers to a line longer than MAX_LINE_BYTES, given its first characters; None: nothing.
Overlong = Callable[[str], str | None]

#: Writes a reply after a delay (s) without holding up other devices: a server that answers many devices
#: from one thread; None: the answering thread sleeps (it answers this device alone).
Deferral = Callable[[float, bytes, Callable[[bytes], object]], None]

#: The longest request line a simulator reads, in bytes without its terminator. Far above any legal request
#: (a built-in one is under 300 bytes: an ACUTROL3000 move of six axes in one line; a profile's template is at
#: most 256 characters and its request prefix 16, so even six joined moves of the longest template stay under
#: 1 700; a bridge request is under 20) and far below what could fill a simulator's memory.
MAX_LINE_BYTES = 4096
#: How much of a discarded line is kept for its answer (a controller on a bus reads the address first).
OVERLONG_HEAD_BYTES = 64
#: A request terminator of None: a line ends at CR, LF or CR LF, whichever comes (a device that reads any of
#: them, so that a client's odd terminator is answered on its own and never joins the next request).
ANY_LINE_END = None
_LINE_END = re.compile(rb"\r\n?|\n")


class LineAnswers:
    """One conversation's reader: the bytes of one client, cut into requests and answered in order."""

    def __init__(self, handle: Handler, request_terminator: bytes | None = b"\n", reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", faults: ReplyFaults | None = None, defer: Deferral | None = None,
                 overlong: Overlong | None = None, strip: bool = True, stale_after_s: float | None = None) -> None:
        self._handle = handle
        self._overlong = overlong
        self._strip = strip
        self._stale_after_s = stale_after_s
        self._last_data_s = 0.0
        self._request_terminator = request_terminator
        self._reply_terminator = reply_terminator if reply_terminator is not None else request_terminator or b"\n"
        self._encoding = encoding
        self._faults = faults
        self._defer = defer
        self._pending = b""
        #: A line (any line end) just ended at a CR that closed a read: an LF opening the next read is its end's.
        self._cr_ended = False
        #: The first bytes of the line being discarded (too long), None while the line is within bounds.
        self._discarding: bytes | None = None
        #: The most bytes ever held between two reads (what the bound keeps small), for tests.
        self.peak_buffered_bytes = 0

    @property
    def buffered_bytes(self) -> int:
        """Bytes held of the line not yet ended: at most MAX_LINE_BYTES and a terminator's first bytes."""
        return len(self._pending) + len(self._discarding or b"")

    def forget_line(self) -> None:
        """Drop the line begun (its client went away)."""
        self._pending, self._discarding, self._cr_ended = b"", None, False

    def feed(self, data: bytes, write: Callable[[bytes], object]) -> None:
        """Take received bytes; answer each complete request through `write`. Each byte is looked at a bounded
        number of times, so a long stream without a terminator costs time in proportion to its length. The
        rest is stored before the first answer goes out: whoever reads an answer finds the reader settled."""
        now_s = time.monotonic()
        if self._stale_after_s is not None and now_s - self._last_data_s > self._stale_after_s:
            self.forget_line()  # the start of a line its client left: dropped
        self._last_data_s = now_s
        if self._cr_ended and data.startswith(b"\n"):
            data = data[1:]  # the LF of a CR LF split between two reads
        buffer = self._pending + data
        requests: list[tuple[str, bool]] = []
        start = 0
        while (found := self._line_end(buffer, start)) is not None:
            requests.append(self._cut(buffer[start:found[0]]))
            start = found[1]
        self._cr_ended = self._request_terminator is None and 0 < start == len(buffer) and buffer.endswith(b"\r")
        self._keep(buffer[start:])
        self.peak_buffered_bytes = max(self.peak_buffered_bytes, self.buffered_bytes)
        for request, overlong in requests:
            reply = self._reply_to(request, overlong)
            if reply is not None:
                self._send(reply.encode(self._encoding, errors="replace") + self._reply_terminator, write)

    def _line_end(self, buffer: bytes, start: int) -> tuple[int, int] | None:
        """(where the next line ends, where the one after it begins), from `start`; None: no end yet."""
        if self._request_terminator is None:  # ANY_LINE_END
            found = _LINE_END.search(buffer, start)
            return None if found is None else (found.start(), found.end())
        end = buffer.find(self._request_terminator, start)
        return None if end < 0 else (end, end + len(self._request_terminator))

    def _reply_to(self, request: str, overlong: bool) -> str | None:
        """The device's answer to a request, or to a line over the bound (`request`: its first characters)."""
        if not overlong:
            return self._handle(request)
        return self._overlong(request) if self._overlong is not None else None

    def _cut(self, line: bytes) -> tuple[str, bool]:
        """A complete line as it is answered: (its text, False), or for a line over the bound (its first
        characters, True)."""
        head, self._discarding = self._discarding, None
        if head is None and len(line) <= MAX_LINE_BYTES:
            return self._text(line), False
        return self._text(line[:OVERLONG_HEAD_BYTES] if head is None else head), True

    def _text(self, line: bytes) -> str:
        text = line.decode(self._encoding, errors="replace")
        return text.strip() if self._strip else text

    def _keep(self, rest: bytes) -> None:
        """Hold the unterminated rest (a line within the bound, and perhaps the first bytes of its terminator),
        or once it passes the bound only its tail, where a terminator split between two reads begins."""
        tail = len(self._request_terminator or b"\n") - 1
        if self._discarding is None and len(rest) <= MAX_LINE_BYTES + tail:
            self._pending = rest
            return
        if self._discarding is None:
            self._discarding = rest[:OVERLONG_HEAD_BYTES]
        self._pending = rest[len(rest) - tail:] if tail else b""

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
