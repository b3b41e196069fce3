"""A simulated turntable controller on a pseudo-terminal, speaking a line-protocol profile."""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.protocols.turntable_line import TurntableProtocol
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer


class SimulatedTurntableServer:
    """Answers each request from the lab's turntable motion at the shared clock's time."""

    def __init__(self, lab: VirtualLab, protocol: TurntableProtocol, identity: str = "accelcal-rig simulated turntable",
                 faults: ReplyFaults | None = None, stall_after_s: float | None = None):
        self._lab = lab
        self._stall_after_s = stall_after_s
        #: The last motion command (move, stop, home) as received, for tests that check the safe state.
        self.last_command: str | None = None
        self._protocol = protocol
        self._identity = identity
        self._patterns = [(name, getattr(protocol, name), getattr(protocol, name).request_pattern())
                          for name in ("identify", "move", "position", "busy", "stop", "home", "fault")]
        if protocol.write_terminator != protocol.read_terminator:
            raise ValueError("the simulated turntable needs one terminator for both directions")
        self._server = PtyLineServer(self._handle, protocol.write_terminator.encode(), "simulated-turntable", faults)
        self.path = self.endpoint = self._server.path
        #: Fault code the controller reports (fault injection sets it).
        self.fault = self._protocol.fault_ok[0]

    def start(self) -> SimulatedTurntableServer:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, request: str) -> str:
        for name, command, pattern in self._patterns:
            match = pattern.fullmatch(request)
            if match is not None:
                if name in ("move", "stop", "home"):
                    self.last_command = request
                try:
                    return self._answer(name, command.answer, match.groupdict())
                except (ValueError, IndexError) as exc:
                    return f"ERR {exc}"
        return f"ERR unknown command {request!r}"

    def _answer(self, name: str, template: str, fields: dict[str, str]) -> str:
        lab, motion = self._lab, self._lab.motion
        with lab.lock:
            now = lab.clock.now()
            n_axes = len(motion.speeds_deg_s)
            axis = int(fields["axis"]) - 1 if "axis" in fields else None
            if axis is not None and not 0 <= axis < n_axes:
                raise ValueError(f"no axis {axis + 1}")
            stalled = self._stall_after_s is not None and now >= self._stall_after_s
            if name == "move" and not stalled and axis is not None:  # a stalled table says OK, stays put
                motion.command_axis(now, axis, float(fields["angle"]))
            elif name == "stop":
                motion.stop(now)
            elif name == "home":
                motion.command(now, np.zeros(n_axes))
            values = {
                "identity": self._identity,
                "angle": float(motion.position_deg(now)[axis]) if axis is not None else 0.0,
                "busy": "0" if motion.in_position(now) else self._protocol.busy_values[0],
                "fault": self.fault,
            }
        return template.format(**values)


def serve_line(lab: VirtualLab, config: TurntableConfig, faults: InstrumentFaults) -> SimulatedTurntableServer:
    """The serial turntable driver's simulator: a controller speaking the config's line protocol."""
    return SimulatedTurntableServer(lab, config.line_protocol(), faults=faults.replies,
                                    stall_after_s=faults.after_s(faults.settings.turntable_stall_after_min))
