"""A simulated LIS3MDL behind a serial bridge, on a pseudo-terminal: the bridge's register requests
(sim/register_bridge_server.py) in front of its register model (`sim/lis3mdl_registers.py`), its map's
read-only registers refused a write as the bridge refuses any part's."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments import lis3mdl as regs
from accelcal_rig.sim.bridge_registers import RegisterMap
from accelcal_rig.sim.faults import InstrumentFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.lis3mdl_registers import SimulatedLis3mdl
from accelcal_rig.sim.register_bridge_server import SimulatedRegisterBridge

REGISTER_MAP = RegisterMap(last=regs.REG_LAST, read_only=regs.READ_ONLY_REGISTERS)


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedRegisterBridge:
    """The simulator of an LIS3MDL DUT behind a serial bridge (its part's `simulator`)."""
    index = [d.serial for d in lab.duts].index(config.serial)
    device = SimulatedLis3mdl(lab, index, wrong_who_am_i=config.serial == faults.settings.sensor_wrong_id)
    return SimulatedRegisterBridge(lab, index, device, REGISTER_MAP, faults.replies)
