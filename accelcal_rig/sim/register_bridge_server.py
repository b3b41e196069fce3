"""A simulated part that the host polls at register level (no block capture), behind a serial bridge on a
pseudo-terminal: the bridge line protocol's register requests (`R`, `W`) in front of the part's register model,
answered as the reference firmware answers them (sim/bridge_requests.py). The greeting is version 3 and names
the part behind the bridge (`ADXL355-BRIDGE 3 part=… …`); `C`/`G` are refused: the host polls the data
registers. The LIS3MDL's simulator is this bridge in front of its register model; its pseudo-terminal plumbing
(`BridgeOnPty`) and its greeting (`bridge_greeting`) are every simulated bridge's, the ADXL355's and the
ICM-42688-P's with their captures too."""

from __future__ import annotations

from typing import Self

from accelcal_rig.instruments.adxl355_transport import BRIDGE_GREETING
from accelcal_rig.sim.bridge_lines import LINE_ENCODING, STALE_LINE_S, overlong_line
from accelcal_rig.sim.bridge_registers import RegisterDevice, RegisterMap, RegisterRequests
from accelcal_rig.sim.bridge_requests import BridgeRequests
from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer

PROTOCOL_VERSION = 3


class BridgeOnPty:
    """A simulated bridge's line protocol on a pseudo-terminal: each line answered by its requests under the lab's
    lock, as the reference firmware's bridge answers it. Every simulated bridge is one (the ADXL355's with its
    capture, a polled part's with registers alone)."""

    def __init__(self, lab: VirtualLab, index: int, requests: BridgeRequests, faults: ReplyFaults | None) -> None:
        self._lab = lab
        self._requests = requests
        self._server = PtyLineServer(self._handle, b"\n", f"simulated-bridge-{lab.duts[index].serial}", faults,
                                     encoding=LINE_ENCODING, overlong=overlong_line, strip=False,
                                     stale_after_s=STALE_LINE_S)
        self.path = self.endpoint = self._server.path

    @property
    def session(self) -> int:
        """How many times a client has come or gone, as the bridge saw it (tests wait on it, not on time)."""
        return self._server.session

    def start(self) -> Self:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, line: str) -> str | None:
        with self._lab.lock:
            return self._requests.answer(line)


class SimulatedRegisterBridge(BridgeOnPty):
    """The bridge in front of one simulated part's registers (no capture: the host polls them)."""

    def __init__(self, lab: VirtualLab, index: int, device: RegisterDevice, registers: RegisterMap,
                 faults: ReplyFaults | None = None) -> None:
        self._part = lab.duts[index].part
        self.device = device
        super().__init__(lab, index, BridgeRequests(self._greeting, RegisterRequests(device, registers),
                                                    self._part.name), faults)

    def _greeting(self) -> str:
        return bridge_greeting(self._part.name)


def bridge_greeting(part: str, capture_samples: int = 0) -> str:
    """A version 3 bridge's greeting naming its part, and its capture buffer where it captures blocks."""
    capture = f" capture={capture_samples}" if capture_samples else ""
    return f"{BRIDGE_GREETING} {PROTOCOL_VERSION} part={part}{capture} accelcal-rig simulated bridge"
