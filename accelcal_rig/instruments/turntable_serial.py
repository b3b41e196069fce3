"""Turntable driver for a line protocol over pyserial (a device path or any pyserial URL)."""

from __future__ import annotations

import re
import time
from typing import Self

import numpy as np

from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.definitions import TurntableDriver
from accelcal_rig.instruments.limits import refuse_non_finite
from accelcal_rig.instruments.line_port import LinePort, describe_endpoint
from accelcal_rig.instruments.retrying import RetryCall
from accelcal_rig.protocols.turntable_line import Command, TurntableProtocol


class SerialTurntable:
    """A turntable of exactly the capabilities its profile has (constant-rate rotation where it has rate
    commands: accelcal_rig.instruments.capabilities), whichever way it is made."""

    def __new__(cls, line: LinePort, endpoint: str, protocol: TurntableProtocol, n_axes: int) -> Self:
        mixins = [_RateTable] if protocol.rotate is not None else []
        return instance_of(composed(cls, mixins) if cls is SerialTurntable else cls)

    def __init__(self, line: LinePort, endpoint: str, protocol: TurntableProtocol, n_axes: int) -> None:
        self._line = line
        self.endpoint = endpoint
        self.protocol = protocol
        self.n_axes = n_axes
        self._retry: RetryCall = lambda operation, reconnect: operation()
        self._set_up = False  # the profile's setup (interlock, mode) goes out before the first move
        self._polls_at_rest = 0
        self._rate_axes: set[int] = set()  # axes a rate command left in rate mode (their interlock closed)

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
        moves = [(axis, float(angle)) for axis, angle in enumerate(np.asarray(angles_deg, dtype=float), start=1)]
        for axis, angle in moves:  # a NaN is refused before anything, the setup included, is sent
            refuse_non_finite(f"turntable ({self.endpoint})", f"axis {axis} to", angle, "°")
        if not self._set_up:
            self._setup()
        p = self.protocol
        self._polls_at_rest = 0
        if p.multi_axis_move:
            line = p.move_separator.join(p.request(p.move, axis=axis, angle=angle) for axis, angle in moves)
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
        self._rate_axes.clear()

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
        self._rate_axes.clear()  # the setup selects position mode

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
        request = self.protocol.request(command, **fields) if request is None else request
        if self.protocol.acknowledgement == "length-prefixed":
            code, text = self._line.ask_block(request)
            if code != 0:
                raise InstrumentError(f"turntable ({self.endpoint}): {request!r} refused: error code {code}"
                                      + (f", {text!r}" if text else ""))
            return {} if command.reply is None else read_reply(self.protocol, command, request, text, self.endpoint)
        if command.reply is None:
            self._line.send(request)
            return {}
        return read_reply(self.protocol, command, request, self._line.ask(request), self.endpoint)


class _RateTable(SerialTurntable):
    """Constant-rate rotation, composed in only for a profile with rate commands. Limits are the caller's
    gate (LimitedTurntable)."""

    def rotate_at(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        """Turn one axis (0-based) at a rate; a profile's setup (interlock) goes out first unless an axis is
        already in rate mode, and the next move sets position mode up again."""
        number = self._axis_number(axis)
        refuse_non_finite(f"turntable ({self.endpoint})", f"axis {number} at", rate_deg_s, " °/s")
        refuse_non_finite(f"turntable ({self.endpoint})", f"axis {number} acceleration", acceleration_deg_s2, " °/s²")
        if not self._set_up and not self._rate_axes:
            self._setup()
        assert self.protocol.rotate is not None
        self._ask(self.protocol.rotate, axis=number, rate=float(rate_deg_s), acceleration=float(acceleration_deg_s2),
                  rate_limit=abs(float(rate_deg_s)))
        self._rate_axes.add(axis)
        self._set_up = False
        self._polls_at_rest = 0

    def read_rate_deg_s(self, axis: int) -> float:
        assert self.protocol.rate is not None
        return float(self._ask(self.protocol.rate, axis=self._axis_number(axis))["rate"])

    def hold(self, axis: int) -> None:
        assert self.protocol.hold is not None
        self._ask(self.protocol.hold, axis=self._axis_number(axis))
        self._polls_at_rest = 0

    def _axis_number(self, axis: int) -> int:
        if not 0 <= axis < self.n_axes:
            raise InstrumentError(f"turntable ({self.endpoint}): no axis {axis} (it has {self.n_axes})")
        return axis + 1


def read_reply(protocol: TurntableProtocol, command: Command, request: str, reply: str,
               endpoint: str) -> dict[str, str]:
    """The values a reply carries (its pattern's named groups); a reply matching the profile's error pattern
    is a refusal, one matching no pattern a garbled line (retried)."""
    if re.search(protocol.error_pattern, reply):
        raise InstrumentError(f"turntable ({endpoint}): {request!r} refused: {reply!r}")
    assert command.reply is not None
    match = re.fullmatch(command.reply, reply)
    if match is None:
        raise TransientInstrumentError(f"turntable ({endpoint}): {request!r}: unexpected reply {reply!r}")
    return {k: v for k, v in match.groupdict().items() if v is not None}


def _is_fault(protocol: TurntableProtocol, reply: str) -> bool:
    """A fault reply: one of `fault_values` where the profile lists them, else anything not `fault_ok`."""
    return reply in protocol.fault_values if protocol.fault_values else reply not in protocol.fault_ok


def _open(config: TurntableConfig, endpoint: str) -> SerialTurntable:
    return SerialTurntable.open(endpoint, config.line_protocol(), len(config.axes), config.baudrate, config.timeout_s)


SERIAL = TurntableDriver("serial", _open, simulator="accelcal_rig.sim.turntable_server:serve_line",
                         protocol="accelcal_rig.protocols.turntable_line")
