"""The sensor drivers' simulator: the simulated part the rig config's `part:` names (its `simulator`), behind
a serial bridge. An ADXL355, ADXL357 or ADXL359 is served exactly as before (`adxl355_bridge_server`)."""

from __future__ import annotations

from typing import Any

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.parts.registry import part
from accelcal_rig.plugins import load_object
from accelcal_rig.sim.faults import InstrumentFaults
from accelcal_rig.sim.lab import VirtualLab


def serve_part_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> Any:
    """The served bridge in front of this DUT's simulated part."""
    dut_part = part(config.part)
    factory = load_object(dut_part.simulator, f"part {dut_part.name!r}'s simulator")
    return factory(lab, config, faults)
