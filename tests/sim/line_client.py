"""A plain client of a simulated line device (not the project's drivers), over loopback TCP or a
pseudo-terminal: bytes out, reply lines in, each with a deadline."""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from accelcal_rig.core.descriptors import read_within

#: Longest a reply may take (generous: a loaded machine; a missing reply fails, it is never waited out).
DEADLINE_S = 10.0


class LineClient:
    def __init__(self, send: Callable[[bytes], None], receive: Callable[[float], bytes]) -> None:
        self._send, self._receive, self._held = send, receive, b""

    def send(self, data: bytes) -> None:
        self._send(data)

    def reply(self, terminator: bytes) -> bytes:
        """The next reply line, terminator included; fails if none comes within DEADLINE_S."""
        end = time.monotonic() + DEADLINE_S
        while terminator not in self._held:
            got = self._receive(end)
            assert got, f"no reply within {DEADLINE_S} s (have {self._held!r})"
            self._held += got
        line, _, self._held = self._held.partition(terminator)
        return line + terminator


@contextmanager
def tcp_client(endpoint: str) -> Iterator[LineClient]:
    host, port = endpoint.rsplit(":", 1)
    with socket.create_connection((host, int(port)), timeout=DEADLINE_S) as connection:
        yield LineClient(connection.sendall, lambda end: connection.recv(65536))


@contextmanager
def pty_client(path: str) -> Iterator[LineClient]:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        yield LineClient(lambda data: _write_all(fd, data), lambda end: read_within(fd, end))
    finally:
        os.close(fd)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]
