"""The whole simulated rig as real endpoints: the chamber on Modbus TCP (127.0.0.1), the turntable and
each sensor bridge on a pseudo-terminal, all backed by one virtual lab on one clock.

A dry run connects the real drivers to these; `rig sim` leaves them up for any Modbus master or serial
terminal. A chamber configured for Modbus RTU is served over Modbus TCP: the same register map and
requests, another framing.
"""

from __future__ import annotations

from typing import Any

from accelcal_rig.config.procedure import SimulatedEffects
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.instruments.connect import Endpoints
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.chamber_server import SimulatedChamberServer
from accelcal_rig.sim.devices import SimulationTruth
from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer


class SimulatedRig:
    def __init__(self, rig: RigConfig, clock: Clock, seed: int,
                 effects: SimulatedEffects = SimulatedEffects()) -> None:
        self.rig = rig
        self.lab = VirtualLab(rig, clock, seed, effects)
        self.truth = SimulationTruth(self.lab)
        faults = rig.simulation.faults

        def reply_faults(name: str) -> ReplyFaults | None:
            return ReplyFaults(faults, name, clock.now) if faults.rate > 0 else None

        def after_s(minutes: float | None) -> float | None:
            return None if minutes is None else minutes * 60.0

        self.chamber = SimulatedChamberServer(self.lab, rig.chamber.register_map(), rig.chamber.device_id,
                                              faults=reply_faults("chamber"),
                                              stall_after_s=after_s(faults.chamber_stall_after_min))
        self.turntable = SimulatedTurntableServer(self.lab, rig.turntable.line_protocol(),
                                                  faults=reply_faults("turntable"),
                                                  stall_after_s=after_s(faults.turntable_stall_after_min))
        self.bridges = {
            s.serial: SimulatedBridgeServer(
                self.lab, i, faults=reply_faults(s.serial), wrong_part_id=s.serial == faults.sensor_wrong_id,
                stuck_after_s=after_s(faults.sensor_stuck_after_min) if s.serial == faults.sensor_stuck else None)
            for i, s in enumerate(rig.fixture.sensors)
        }
        self._started: list[SimulatedChamberServer | SimulatedTurntableServer | SimulatedBridgeServer] = []

    def start(self) -> Endpoints:
        try:
            servers: list[SimulatedChamberServer | SimulatedTurntableServer | SimulatedBridgeServer] = [
                self.chamber, self.turntable, *self.bridges.values()]
            for server in servers:
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
        return Endpoints(self.chamber.endpoint, self.turntable.path,
                         {serial: bridge.path for serial, bridge in self.bridges.items()}, chamber_over_tcp=True)

    def describe(self) -> dict[str, Any]:
        """The endpoints as `rig sim` prints them."""
        return {
            "chamber": {"protocol": "modbus-tcp", "host": self.chamber.host, "port": self.chamber.port,
                        "device_id": self.rig.chamber.device_id, "profile": self.rig.chamber.profile},
            "turntable": {"protocol": self.rig.turntable.protocol, "device": self.turntable.path},
            "sensors": {serial: {"protocol": "adxl355-bridge", "device": bridge.path}
                        for serial, bridge in self.bridges.items()},
        }
