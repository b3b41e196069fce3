"""The ACME chamber's simulator: a TCP line server answering from the virtual lab."""

import socketserver
import threading


class _Handler(socketserver.StreamRequestHandler):
    def handle(self) -> None:
        for raw in self.rfile:
            self.wfile.write((self.server.answer(raw.decode().strip()) + "\n").encode())


class AcmeServer(socketserver.ThreadingTCPServer):
    daemon_threads = True

    def __init__(self, lab) -> None:
        super().__init__(("127.0.0.1", 0), _Handler)
        self.lab = lab

    @property
    def endpoint(self) -> str:
        host, port = self.server_address[:2]
        return f"{host}:{port}"

    def answer(self, request: str) -> str:
        with self.lab.lock:
            if request == "*IDN?":
                return "ACME TC-1"
            if request == "PV?":
                return f"{self.lab.thermal.air_c(self.lab.clock.now()):.2f}"
            if request == "SP?":
                return f"{self.lab.thermal.setpoint_c:.2f}"
            if request.startswith("SP "):
                self.lab.thermal.set_setpoint(self.lab.clock.now(), float(request[3:]))
                return "OK"
            if request == "ALARM?":
                return "0"
            return "ERR unknown request"

    def start(self) -> "AcmeServer":
        threading.Thread(target=self.serve_forever, daemon=True).start()
        return self

    def stop(self) -> None:
        self.shutdown()
        self.server_close()


def serve(lab, config, faults) -> AcmeServer:
    return AcmeServer(lab)
