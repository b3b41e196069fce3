"""What a driver ships, as the registry (accelcal_rig.plugins) finds it: how to open it on a rig config's
entry and endpoint, the simulator a dry run puts at the other end of its wire, and its protocol's home.

`simulator` is a "module:attribute" reference, imported only for a dry run, to a factory
`(lab, config, faults) → server` whose server has `start()`, `stop()` and `endpoint` (see accelcal_rig.sim);
`simulated_by` names the driver a dry run talks to that server with, when not this one (a Modbus RTU
chamber is simulated on Modbus TCP).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from accelcal_rig.config.rig import ChamberConfig, SensorConfig, TurntableConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.instruments.adxl355_transport import RegisterTransport
from accelcal_rig.instruments.interfaces import Chamber, Turntable


@dataclass(frozen=True)
class ChamberDriver:
    name: str
    open: Callable[[ChamberConfig, str], Chamber]            #: (its config, endpoint) → connected
    simulator: str
    protocol: str                                            #: where the protocol is defined
    simulated_by: str | None = None


@dataclass(frozen=True)
class TurntableDriver:
    name: str
    open: Callable[[TurntableConfig, str], Turntable]
    simulator: str
    protocol: str
    simulated_by: str | None = None


@dataclass(frozen=True)
class SensorDriver:
    """How a DUT's registers are reached (the part behind them is the rig config's `part:`)."""

    name: str
    open: Callable[[SensorConfig, str, int, Clock], RegisterTransport]  #: (config, endpoint, attempts, clock)
    simulator: str
    protocol: str
    simulated_by: str | None = None
