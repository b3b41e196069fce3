"""A simulated ICM-42688-P behind a serial bridge, on a pseudo-terminal: the bridge line protocol's register
requests (`R`, `W`) in front of the register model (`sim/icm42688_registers.py`), answered as the reference
firmware answers them (sim/bridge_requests.py). The greeting is version 3 and names the part behind the bridge
(`ADXL355-BRIDGE 3 part=icm42688p …`); an ICM-42688-P bridge captures no blocks (`C`/`G` refused): the host polls
the data registers."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.adxl355_transport import BRIDGE_GREETING
from accelcal_rig.sim.bridge_lines import LINE_ENCODING, STALE_LINE_S, overlong_line
from accelcal_rig.sim.bridge_registers import RegisterMap, RegisterRequests
from accelcal_rig.sim.bridge_requests import BridgeRequests
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.icm42688_registers import SimulatedIcm42688
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer

PROTOCOL_VERSION = 3
#: The register map as the bridge enforces it: bank 0's read-only registers; banks by REG_BANK_SEL.
REGISTER_MAP = RegisterMap(last=regs.REG_LAST, read_only=regs.READ_ONLY_REGISTERS, bank_select=regs.REG_BANK_SEL)


class SimulatedIcm42688Bridge:
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ICM-42688-P."""

    def __init__(self, lab: VirtualLab, index: int, faults: ReplyFaults | None = None,
                 wrong_who_am_i: bool = False) -> None:
        self._lab = lab
        self._part = lab.duts[index].part
        self.device = SimulatedIcm42688(lab, index, wrong_who_am_i)
        self._requests = BridgeRequests(self._greeting, RegisterRequests(self.device, REGISTER_MAP), self._part.name)
        self._server = PtyLineServer(self._handle, b"\n", f"simulated-bridge-{lab.duts[index].serial}", faults,
                                     encoding=LINE_ENCODING, overlong=overlong_line, strip=False,
                                     stale_after_s=STALE_LINE_S)
        self.path = self.endpoint = self._server.path

    @property
    def session(self) -> int:
        """How many times a client has come or gone, as the bridge saw it (tests wait on it, not on time)."""
        return self._server.session

    def start(self) -> SimulatedIcm42688Bridge:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, line: str) -> str | None:
        with self._lab.lock:
            return self._requests.answer(line)

    def _greeting(self) -> str:
        return f"{BRIDGE_GREETING} {PROTOCOL_VERSION} part={self._part.name} accelcal-rig simulated bridge"


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedIcm42688Bridge:
    """The simulator of an ICM-42688-P DUT behind a serial bridge (its part's `simulator`)."""
    index = [d.serial for d in lab.duts].index(config.serial)
    return SimulatedIcm42688Bridge(lab, index, faults.replies,
                                   wrong_who_am_i=config.serial == faults.settings.sensor_wrong_id)
