"""A simulated ICM-42688-P behind a serial bridge, on a pseudo-terminal: the bridge line protocol's register
requests (`R`, `W`) in front of the register model (`sim/icm42688_registers.py`). The greeting is version 3
and names the part behind the bridge (`ADXL355-BRIDGE 3 part=icm42688p …`); an ICM-42688-P bridge captures
no blocks (no `C`/`G`): the host polls the data registers."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments.adxl355_transport import BRIDGE_GREETING
from accelcal_rig.sim.bridge_requests import overlong_request, register_request
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.icm42688_registers import SimulatedIcm42688
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer

PROTOCOL_VERSION = 3


class SimulatedIcm42688Bridge:
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ICM-42688-P."""

    def __init__(self, lab: VirtualLab, index: int, faults: ReplyFaults | None = None,
                 wrong_who_am_i: bool = False) -> None:
        self._lab = lab
        self._part = lab.duts[index].part
        self.device = SimulatedIcm42688(lab, index, wrong_who_am_i)
        self._server = PtyLineServer(self._handle, b"\n", f"simulated-bridge-{lab.duts[index].serial}", faults,
                                     overlong=overlong_request)
        self.path = self.endpoint = self._server.path

    def start(self) -> SimulatedIcm42688Bridge:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, request: str) -> str:
        words = request.split()
        try:
            with self._lab.lock:
                if words == ["?"]:
                    return f"{BRIDGE_GREETING} {PROTOCOL_VERSION} part={self._part.name} accelcal-rig simulated bridge"
                reply = register_request(self.device, words)
                if reply is not None:
                    return reply
        except ValueError as exc:
            return f"!{exc}"
        return f"!unknown request {request!r}"


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedIcm42688Bridge:
    """The simulator of an ICM-42688-P DUT behind a serial bridge (its part's `simulator`)."""
    index = [d.serial for d in lab.duts].index(config.serial)
    return SimulatedIcm42688Bridge(lab, index, faults.replies,
                                   wrong_who_am_i=config.serial == faults.settings.sensor_wrong_id)
