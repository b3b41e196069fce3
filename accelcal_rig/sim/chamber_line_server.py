"""A simulated chamber controller speaking a line-protocol profile, generated from the profile itself: each
request is recognised by its command's template in every spelling the profile's dialect takes, and answered
with the command's answer template, from the virtual lab at the shared clock's time; what the makers'
clients send beyond the profile is answered by the dialect's extras (sim/line_extras.py). On loopback TCP
(a controller's Ethernet port) or a pty (its serial port)."""

from __future__ import annotations

from typing import Literal

from accelcal_rig.config.rig import ChamberConfig
from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol, Operation
from accelcal_rig.protocols.line_templates import finite_number
from accelcal_rig.sim.controller_extras import Unknown, Unsupported
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.line_answers import ANY_LINE_END
from accelcal_rig.sim.line_extras import extras_for
from accelcal_rig.sim.pty_line_server import PtyLineServer
from accelcal_rig.sim.tcp_line_server import TcpLineServer

_WRITES: frozenset[Operation] = frozenset({"write_setpoint", "power_on", "power_off", "purge_on", "purge_off"})


class SimulatedLineChamberServer:
    def __init__(self, lab: VirtualLab, protocol: ChamberLineProtocol, transport: Literal["tcp", "pty"] = "tcp",
                 identity: str = "accelcal-rig simulated chamber", units: str | None = None,
                 faults: ReplyFaults | None = None, stall_after_s: float | None = None) -> None:
        self._lab = lab
        self._protocol = protocol
        self._patterns = protocol.request_patterns()
        #: What the controller names itself (SIMSERV's type text, the controller field of ESPEC's TYPE?).
        self.identity = identity
        #: What the controller says its units are (a test sets °F to see the driver refuse it).
        self.units = protocol.units_celsius if units is None else units
        #: A controller whose panel locks remote writes (local mode; ESPEC: data protection) refuses them (tests set it).
        self.local_mode = False
        #: Active alarms and warnings (tests set them): SIMSERV's status, ESPEC's alarm count.
        self.alarms = 0
        self.warnings = 0
        #: The chamber's own range (ESPEC's TYPE? maximum): a client sets the controller's limits within it.
        self.rated_limits_c: tuple[float, float] = lab.controller_limits_c
        #: The last set point written over the wire, for tests that check the safe state.
        self.last_setpoint_c: float | None = None
        self._extras = extras_for(protocol, lab, self)
        self._stall_after_s = stall_after_s
        requests_end = ANY_LINE_END if protocol.any_line_end else protocol.write_terminator.encode(protocol.encoding)
        replies_end = protocol.read_terminator.encode(protocol.encoding)
        server = TcpLineServer if transport == "tcp" else PtyLineServer
        self._server: TcpLineServer | PtyLineServer = server(self._handle, requests_end, "simulated-chamber", faults,
                                                             replies_end, protocol.encoding,
                                                             overlong=self.overlong_answer)

    @property
    def endpoint(self) -> str:
        """`host:port` on TCP, the device path on a pty: what the driver's config names."""
        return self._server.endpoint if isinstance(self._server, TcpLineServer) else self._server.path

    @property
    def buffered_bytes(self) -> int:
        """Bytes held of requests not yet ended (bounded: sim/line_answers.py), for tests."""
        return self._server.buffered_bytes

    @property
    def peak_buffered_bytes(self) -> int:
        """The most bytes ever held of an unended request between two reads, for tests."""
        return self._server.peak_buffered_bytes

    def start(self) -> SimulatedLineChamberServer:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    # ------------------------------------------------------------------ requests
    def _handle(self, request: str) -> str | None:
        prefix = self._protocol.request_prefix
        if not request.startswith(prefix):
            return None  # addressed to another controller on the bus
        request = request[len(prefix):]
        for operation, command, pattern in self._patterns:
            match = pattern.fullmatch(request)  # type: ignore[attr-defined]
            if match is None:
                continue
            if operation in _WRITES and self.local_mode and self._protocol.local_mode_answer is not None:
                return self._protocol.local_mode_answer
            try:
                value = finite_number(match["value"]) if "value" in match.groupdict() else None
            except ValueError:  # `nan`, `inf`, `1e400`, `1_0`: refused as any request it cannot read, set point
                return self._not_a_number(request)  # kept
            values = self._serve(operation, value)
            return None if command.answer is None else command.answer.format(request=request, **values)
        with self._lab.lock:
            self._lab.moisture.dew_point_c(self._lab.clock.now())
            extra = self._extras.answer(request)
        if isinstance(extra, Unsupported) and self._protocol.unsupported_answer is not None:
            return self._protocol.unsupported_answer
        return self._protocol.unknown_command_answer if isinstance(extra, Unknown | Unsupported) else extra

    def _not_a_number(self, request: str) -> str | None:
        """A write whose set point is no number: answered as an unknown request, unless it is a word the
        controller has for something not simulated (ESPEC's `TEMP, SOFF`, temperature control off)."""
        with self._lab.lock:
            extra = self._extras.answer(request)
        if isinstance(extra, Unsupported) and self._protocol.unsupported_answer is not None:
            return self._protocol.unsupported_answer
        return self._protocol.unknown_command_answer

    def overlong_answer(self, head: str) -> str | None:
        """A line too long to be a request (its first characters `head`): answered as an unknown request by a
        controller it is addressed to, unanswered by the others on the bus."""
        return self._protocol.unknown_command_answer if head.startswith(self._protocol.request_prefix) else None

    def _serve(self, operation: Operation, value: float | None) -> dict[str, object]:
        """Carry out a request (`value`: the set point it writes, already read) and give its answer's fields."""
        lab = self._lab
        with lab.lock:
            now = lab.clock.now()
            lab.moisture.dew_point_c(now)  # the air's moisture follows the air, request by request
            if operation == "write_setpoint" and value is not None:
                self.write_setpoint(now, value)
            elif operation in ("power_on", "power_off"):
                lab.thermal.set_power(now, operation == "power_on")
            elif operation in ("purge_on", "purge_off"):
                lab.moisture.set_purge(now, operation == "purge_on")
            if operation in _WRITES:
                self._extras.carried_out(operation)
            shown = self.last_setpoint_c if self.last_setpoint_c is not None else lab.thermal.setpoint_c
            low, high = lab.controller_limits_c
            quiet = "0" if self._protocol.alarm_bits is not None else self._protocol.alarm_inactive[0]
            values: dict[str, object] = {"identity": self.identity, "sp": shown, "low": low, "high": high,
                                         "alarm": quiet, "units": self.units, "sensors": "T",
                                         "value": shown if value is None else value, "pv": 0.0, "humidity": 0.0,
                                         "rated_high": self.rated_limits_c[1], "humidity_sp": "0",
                                         "humidity_high": 100.0, "humidity_low": 0.0, **self._extras.values()}
            if operation in ("read_temperature", "read_setpoint", "read_low_limit", "read_high_limit"):
                values["pv"] = lab.chamber_reading_c()  # measured only when a reply may carry it (it draws noise)
            if operation == "humidity":
                values["humidity"] = lab.chamber_humidity_pct()
        return values

    def write_setpoint(self, now: float, setpoint_c: float) -> None:
        """Take a set point: clamped to the controller's limits where the profile reads them, followed by the
        chamber unless it stalled (the lab's lock held)."""
        if self._protocol.read_low_limit is not None:  # a controller with limits clamps to them, silently
            low, high = self._lab.controller_limits_c
            setpoint_c = min(max(setpoint_c, low), high)
        if self._stall_after_s is None or now < self._stall_after_s:
            self._lab.thermal.set_setpoint(now, setpoint_c)  # a stalled chamber takes it but does not follow
        self.last_setpoint_c = setpoint_c


def serve_line(lab: VirtualLab, config: ChamberConfig, faults: InstrumentFaults) -> SimulatedLineChamberServer:
    """The line chamber driver's simulator: a controller speaking the config's profile on loopback TCP."""
    return SimulatedLineChamberServer(lab, config.line_protocol(), "tcp", identity=f"accelcal-rig simulated "
                                      f"{config.profile}", faults=faults.replies,
                                      stall_after_s=faults.after_s(faults.settings.chamber_stall_after_min))
