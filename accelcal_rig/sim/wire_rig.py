"""The whole simulated rig as real endpoints, each instrument served by the simulator its driver names
(accelcal_rig.plugins): built in, the chamber on Modbus TCP or its line protocol on TCP (127.0.0.1), the
turntable and each sensor bridge on a pseudo-terminal, all backed by one virtual lab on one clock.

A dry run connects the real drivers to these; `rig sim` leaves them up for any Modbus master or serial
terminal. A driver whose simulator speaks another framing says which driver talks to it (`simulated_by`:
a chamber configured for Modbus RTU is served over Modbus TCP, the same register map and requests).
"""

from __future__ import annotations

from typing import Any, Protocol

from accelcal_rig.config.procedure import SimulatedEffects
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.instruments.connect import Endpoints
from accelcal_rig.plugins import Kind, load_driver, load_object
from accelcal_rig.sim.devices import SimulationTruth
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab


class ServedInstrument(Protocol):
    """What a driver's simulator factory returns: a server at an endpoint its driver can open."""

    @property
    def endpoint(self) -> str: ...

    def start(self) -> Any: ...
    def stop(self) -> None: ...


class SimulatedRig:
    def __init__(self, rig: RigConfig, clock: Clock, seed: int,
                 effects: SimulatedEffects = SimulatedEffects()) -> None:
        self.rig = rig
        self.lab = VirtualLab(rig, clock, seed, effects)
        self.truth = SimulationTruth(self.lab)
        settings = rig.simulation.faults

        def served(kind: Kind, driver: str, config: Any, name: str) -> tuple[ServedInstrument, str]:
            """(the instrument's simulator, the driver that talks to it)."""
            definition = load_driver(kind, driver)
            factory = load_object(definition.simulator, f"the simulator of {kind} driver {driver!r}")
            replies = ReplyFaults(settings, name, clock.now) if settings.rate > 0 else None
            return factory(self.lab, config, InstrumentFaults(replies, settings)), definition.simulated_by or driver

        self.chamber, chamber_driver = served("chamber", rig.chamber.driver, rig.chamber, "chamber")
        self.turntable, turntable_driver = served("turntable", rig.turntable.driver, rig.turntable, "turntable")
        bridges = {s.serial: served("sensor", s.driver, s, s.serial) for s in rig.fixture.sensors}
        self.bridges = {serial: server for serial, (server, _) in bridges.items()}
        self._drivers = {"chamber": chamber_driver, "turntable": turntable_driver,
                         **{serial: driver for serial, (_, driver) in bridges.items()}}
        self._started: list[ServedInstrument] = []

    def start(self) -> Endpoints:
        try:
            for server in [self.chamber, self.turntable, *self.bridges.values()]:
                server.start()
                self._started.append(server)
        except BaseException:
            self.stop()
            raise
        return self.endpoints

    def stop(self) -> None:
        while self._started:
            self._started.pop().stop()

    @property
    def endpoints(self) -> Endpoints:
        return Endpoints(self.chamber.endpoint, self.turntable.endpoint,
                         {serial: bridge.endpoint for serial, bridge in self.bridges.items()}, dict(self._drivers))

    def describe(self) -> dict[str, Any]:
        """The endpoints as `rig sim` prints them."""
        chamber: dict[str, Any] = {"protocol": self._drivers["chamber"], "endpoint": self.chamber.endpoint}
        if self._drivers["chamber"] in ("modbus-tcp", "line"):
            host, _, port = self.chamber.endpoint.rpartition(":")
            chamber |= {"host": host, "port": int(port), "profile": self.rig.chamber.profile}
        if self._drivers["chamber"] == "modbus-tcp":
            chamber["device_id"] = self.rig.chamber.device_id
        return {
            "chamber": chamber,
            "turntable": {"protocol": self.rig.turntable.protocol, "device": self.turntable.endpoint},
            "sensors": {serial: {"protocol": "adxl355-bridge", "device": bridge.endpoint}
                        for serial, bridge in self.bridges.items()},
        }
