"""Request/reply byte pairs in memory, in place of a serial port (PyMeasure's `expected_protocol` is the
model): the driver under test talks to an `ExpectedPort`, which checks every byte written against the next
request of the conversation and answers with its reply. A new line-protocol driver is written against
these first; its tests over pseudo-terminals come after."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from accelcal_rig.instruments.line_port import LinePort


class ExpectedPort:
    """Stands in for a pyserial port. `conversation`: (request bytes, reply bytes, or None for silence)."""

    timeout = 0.01  # seconds a silent reply costs

    def __init__(self, conversation: Sequence[tuple[bytes, bytes | None]]) -> None:
        self._left = list(conversation)
        self._reply = bytearray()
        self.closed = False

    @property
    def in_waiting(self) -> int:
        return len(self._reply)

    def reset_input_buffer(self) -> None:
        self._reply.clear()

    def write(self, data: bytes) -> int:
        assert self._left, f"wrote {data!r} after the conversation ended"
        request, reply = self._left.pop(0)
        assert data == request, f"wrote {data!r}, expected {request!r}"
        self._reply += reply or b""
        return len(data)

    def read(self, size: int = 1) -> bytes:
        chunk = bytes(self._reply[:size])
        del self._reply[:size]
        return chunk

    def close(self) -> None:
        self.closed = True

    def assert_finished(self) -> None:
        assert not self._left, f"never sent: {[request for request, _ in self._left]}"


@contextmanager
def expected_protocol(conversation: Sequence[tuple[bytes, bytes | None]], name: str = "instrument (memory)",
                      write_terminator: str = "\n", read_terminator: str = "\n",
                      encoding: str = "ascii") -> Iterator[LinePort]:
    """A LinePort over an ExpectedPort; on leaving, every request of the conversation must have been sent."""
    port = ExpectedPort(conversation)
    yield LinePort(port, name, write_terminator, read_terminator, encoding=encoding)  # type: ignore[arg-type]
    port.assert_finished()
