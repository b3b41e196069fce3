"""Turntable driver for a line protocol over pyserial (a device path or any pyserial URL)."""

from __future__ import annotations

import re
import time

import numpy as np

from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.definitions import TurntableDriver
from accelcal_rig.instruments.line_port import LinePort, describe_endpoint
from accelcal_rig.instruments.retrying import RetryCall
from accelcal_rig.protocols.turntable_line import Command, TurntableProtocol


class SerialTurntable:
    def __init__(self, line: LinePort, endpoint: str, protocol: TurntableProtocol, n_axes: int) -> None:
        self._line = line
        self.endpoint = endpoint
        self.protocol = protocol
        self.n_axes = n_axes
        self._error = re.compile(protocol.error_pattern)
        self._retry: RetryCall = lambda operation, reconnect: operation()
        self._set_up = False  # the profile's setup (interlock, mode) goes out before the first move
        self._polls_at_rest = 0

    @classmethod
    def open(cls, endpoint: str, protocol: TurntableProtocol, n_axes: int, baudrate: int = 9600,
             timeout_s: float = 2.0) -> SerialTurntable:
        line = LinePort.open(endpoint, "turntable", baudrate, timeout_s, protocol.write_terminator,
                             protocol.read_terminator)
        return cls(line, describe_endpoint(endpoint), protocol, n_axes)

    # ------------------------------------------------------------------ the Turntable interface
    def identify(self) -> str:
        return self._ask(self.protocol.identify)["identity"]

    def move_to(self, angles_deg: np.ndarray) -> None:
        """Command every axis (in one line where the profile moves them together); limits are the caller's
        gate (LimitedTurntable)."""
        if not self._set_up:
            self._setup()
        p = self.protocol
        moves = [(axis, float(angle)) for axis, angle in enumerate(np.asarray(angles_deg, dtype=float), start=1)]
        self._polls_at_rest = 0
        if p.multi_axis_move:
            line = p.move_separator.join(p.move.send.format(axis=axis, angle=angle) for axis, angle in moves)
            self._ask(p.move, request=line)
        else:
            for axis, angle in moves:
                self._ask(p.move, axis=axis, angle=angle)

    def read_angles_deg(self) -> np.ndarray:
        return np.array([float(self._ask(self.protocol.position, axis=axis)["angle"])
                         for axis in range(1, self.n_axes + 1)])

    def in_position(self) -> bool:
        """Not busy, or every axis at rest for the profile's polls; a controller fault (of any axis, named)
        is raised, never waited out."""
        p = self.protocol
        for axis, reply in self._each(p.fault):
            fault = reply["fault"]
            if _is_fault(p, fault):
                where = f"axis {axis}: " if axis else ""
                raise InstrumentError(f"turntable ({self.endpoint}): {where}controller fault {fault}")
        if p.busy is not None:
            return not any(reply["busy"] in p.busy_values for _, reply in self._each(p.busy))
        at_rest = all(abs(float(reply["rate"])) < p.at_rest_deg_s for _, reply in self._each(p.rate))
        self._polls_at_rest = self._polls_at_rest + 1 if at_rest else 0
        return self._polls_at_rest >= p.at_rest_polls

    def stop(self) -> None:
        """Stop every axis; a profile's stop may leave another mode, so the next move sets it up again."""
        self._set_up = False
        self._each(self.protocol.stop)

    def close(self) -> None:
        self._line.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each request on its own (a move of three axes is three requests, each safe to repeat)."""
        self._retry = call

    def reconnect(self) -> None:
        """A controller that dropped off the line may have lost its mode: the next move sets it up again."""
        self._set_up = False
        self._line.reconnect()

    def _setup(self) -> None:
        """The profile's setup commands (close the interlock, select position mode), each given its pause."""
        for command in self.protocol.setup:
            for axis in range(1, self.n_axes + 1) if command.per_axis else (None,):
                self._ask(command, axis=axis)
                time.sleep(self.protocol.setup_pause_s)
        self._set_up = True

    def _each(self, command: Command | None) -> list[tuple[int | None, dict[str, str]]]:
        """A command sent once per axis if it names one (1-based axis numbers), else once (axis None)."""
        assert command is not None
        if command.per_axis:
            return [(axis, self._ask(command, axis=axis)) for axis in range(1, self.n_axes + 1)]
        return [(None, self._ask(command))]

    # ------------------------------------------------------------------ wire
    def _ask(self, command: Command, request: str | None = None, **fields: object) -> dict[str, str]:
        return self._retry(lambda: self._ask_once(command, request, **fields), self.reconnect)

    def _ask_once(self, command: Command, request: str | None, **fields: object) -> dict[str, str]:
        request = command.send.format(**fields) if request is None else request
        if command.reply is None:
            self._line.send(request)
            return {}
        reply = self._line.ask(request)
        if self._error.search(reply):
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r} refused: {reply!r}")
        match = re.fullmatch(command.reply, reply)
        if match is None:
            raise TransientInstrumentError(f"turntable ({self.endpoint}): {request!r}: unexpected reply {reply!r}")
        return {k: v for k, v in match.groupdict().items() if v is not None}


def _is_fault(protocol: TurntableProtocol, reply: str) -> bool:
    """A fault reply: one of `fault_values` where the profile lists them, else anything not `fault_ok`."""
    return reply in protocol.fault_values if protocol.fault_values else reply not in protocol.fault_ok


def _open(config: TurntableConfig, endpoint: str) -> SerialTurntable:
    return SerialTurntable.open(endpoint, config.line_protocol(), len(config.axes), config.baudrate, config.timeout_s)


SERIAL = TurntableDriver("serial", _open, simulator="accelcal_rig.sim.turntable_server:serve_line",
                         protocol="accelcal_rig.protocols.turntable_line")
