"""A simulated ICM-42688-P behind a serial bridge, on a pseudo-terminal: the bridge's register requests
(sim/register_bridge_server.py) in front of its register model (`sim/icm42688_registers.py`), its register map
as the reference firmware enforces it (bank 0's read-only registers; banks by REG_BANK_SEL)."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.sim.bridge_registers import RegisterMap
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.icm42688_registers import SimulatedIcm42688
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.register_bridge_server import SimulatedRegisterBridge

#: The register map as the bridge enforces it: bank 0's read-only registers; banks by REG_BANK_SEL.
REGISTER_MAP = RegisterMap(last=regs.REG_LAST, read_only=regs.READ_ONLY_REGISTERS, bank_select=regs.REG_BANK_SEL)


class SimulatedIcm42688Bridge(SimulatedRegisterBridge):
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ICM-42688-P."""

    def __init__(self, lab: VirtualLab, index: int, faults: ReplyFaults | None = None,
                 wrong_who_am_i: bool = False) -> None:
        super().__init__(lab, index, SimulatedIcm42688(lab, index, wrong_who_am_i), REGISTER_MAP, faults)


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedIcm42688Bridge:
    """The simulator of an ICM-42688-P DUT behind a serial bridge (its part's `simulator`)."""
    index = [d.serial for d in lab.duts].index(config.serial)
    return SimulatedIcm42688Bridge(lab, index, faults.replies,
                                   wrong_who_am_i=config.serial == faults.settings.sensor_wrong_id)
