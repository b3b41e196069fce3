"""A simulated ICM-42688-P behind a serial bridge, on a pseudo-terminal: the bridge's register requests in front of
its register model (`sim/icm42688_registers.py`), its register map as the reference firmware enforces it (bank 0's
read-only registers; banks by REG_BANK_SEL; a burst from FIFO_DATA stays on it), and the bridge's own capture of
the part's FIFO packets (`C`, `G`), answered as the reference firmware answers them."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.sim.bridge_capture import CaptureRequests, CaptureRules
from accelcal_rig.sim.bridge_refusals import fifo_not_in_packets
from accelcal_rig.sim.bridge_registers import RegisterMap, RegisterRequests
from accelcal_rig.sim.bridge_requests import BridgeRequests
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.icm42688_registers import CAPTURE_CAPACITY_SAMPLES, SimulatedIcm42688
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.register_bridge_server import BridgeOnPty, bridge_greeting

#: The register map as the bridge enforces it: bank 0's read-only registers; banks by REG_BANK_SEL; FIFO_DATA.
REGISTER_MAP = RegisterMap(last=regs.REG_LAST, read_only=regs.READ_ONLY_REGISTERS, burst_stays=regs.REG_FIFO_DATA,
                           bank_select=regs.REG_BANK_SEL)
#: Writes that end a running capture: what the FIFO holds, the sensors' power, rate and range, the interface's
#: byte order, a reset, another bank.
STREAM_REGISTERS = frozenset({regs.REG_DEVICE_CONFIG, regs.REG_FIFO_CONFIG, regs.REG_SIGNAL_PATH_RESET,
                              regs.REG_INTF_CONFIG0, regs.REG_PWR_MGMT0, regs.REG_GYRO_CONFIG0, regs.REG_ACCEL_CONFIG0,
                              regs.REG_FIFO_CONFIG1, regs.REG_BANK_SEL})


class SimulatedIcm42688Bridge(BridgeOnPty):
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ICM-42688-P."""

    def __init__(self, lab: VirtualLab, index: int, faults: ReplyFaults | None = None,
                 wrong_who_am_i: bool = False) -> None:
        self.device = device = SimulatedIcm42688(lab, index, wrong_who_am_i)
        capture = CaptureRequests(device, CAPTURE_CAPACITY_SAMPLES,
                                  CaptureRules(regs.REG_FIFO_DATA, STREAM_REGISTERS, self._not_ready))
        registers = RegisterRequests(device, REGISTER_MAP, capture=capture)
        greeting = bridge_greeting(lab.duts[index].part.name, CAPTURE_CAPACITY_SAMPLES)
        super().__init__(lab, index, BridgeRequests(lambda: greeting, registers, lab.duts[index].part.name, capture),
                         faults)

    def _not_ready(self) -> str | None:
        """A C needs the FIFO on, in packets of both sensors (the firmware reads FIFO_CONFIG and FIFO_CONFIG1)."""
        if self.device.fifo_packets:
            return None
        return fifo_not_in_packets(self.device.read(regs.REG_FIFO_CONFIG, 1)[0],
                                   self.device.read(regs.REG_FIFO_CONFIG1, 1)[0])


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedIcm42688Bridge:
    """The simulator of an ICM-42688-P DUT behind a serial bridge (its part's `simulator`)."""
    index = [d.serial for d in lab.duts].index(config.serial)
    return SimulatedIcm42688Bridge(lab, index, faults.replies,
                                   wrong_who_am_i=config.serial == faults.settings.sensor_wrong_id)
