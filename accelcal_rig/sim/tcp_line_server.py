"""A line device on the network: a TCP server on loopback whose connections a simulator answers line by
line (a chamber controller's Ethernet port, or a serial-to-Ethernet bridge in front of one). Each connection
holds at most one bounded line (sim/line_answers.py, MAX_LINE_BYTES)."""

from __future__ import annotations

import socketserver
import threading
from collections.abc import Callable

from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.line_answers import Handler, LineAnswers, Overlong


class _Connection(socketserver.BaseRequestHandler):
    server: _Server

    def handle(self) -> None:
        answers = self.server.answers_for()
        self.server.connections.add(answers)
        try:
            while True:
                data = self.request.recv(65536)
                if not data:
                    return
                answers.feed(data, self.request.sendall)
        except OSError:
            return
        finally:
            self.server.connections.discard(answers)


class _Server(socketserver.ThreadingTCPServer):
    allow_reuse_address = True
    daemon_threads = True

    def __init__(self, address: tuple[str, int], answers_for: Callable[[], LineAnswers]) -> None:
        self.answers_for = answers_for
        #: Each open connection's side of the conversation (what it holds of an unended line).
        self.connections: set[LineAnswers] = set()
        super().__init__(address, _Connection)


class TcpLineServer:
    """Each connection is answered on its own thread (the handler takes the lab's lock); a client that
    reconnects is served anew."""

    def __init__(self, handle: Handler, terminator: bytes | None = b"\n", name: str = "tcp",
                 faults: ReplyFaults | None = None, reply_terminator: bytes | None = None,
                 encoding: str = "utf-8", host: str = "127.0.0.1", port: int = 0,
                 overlong: Overlong | None = None) -> None:
        self._server = _Server((host, port), lambda: LineAnswers(handle, terminator, reply_terminator, encoding,
                                                                 faults, overlong=overlong))
        self.host, self.port = self._server.socket.getsockname()[:2]
        self._thread = threading.Thread(target=self._server.serve_forever, kwargs={"poll_interval": 0.05},
                                        name=name, daemon=True)

    @property
    def endpoint(self) -> str:
        return f"{self.host}:{self.port}"

    @property
    def buffered_bytes(self) -> int:
        """Bytes held of unended lines, over every open connection (each bounded)."""
        return sum(answers.buffered_bytes for answers in list(self._server.connections))

    @property
    def peak_buffered_bytes(self) -> int:
        """The most bytes any open connection has held of an unended line, for tests."""
        return max((answers.peak_buffered_bytes for answers in list(self._server.connections)), default=0)

    def start(self) -> TcpLineServer:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(5.0)
