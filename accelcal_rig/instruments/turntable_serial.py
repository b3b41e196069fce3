"""Turntable driver for a line protocol over pyserial (a device path or any pyserial URL)."""

from __future__ import annotations

import re

import numpy as np

from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.definitions import TurntableDriver
from accelcal_rig.instruments.line_port import LinePort
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

    @classmethod
    def open(cls, endpoint: str, protocol: TurntableProtocol, n_axes: int, baudrate: int = 9600,
             timeout_s: float = 2.0) -> SerialTurntable:
        line = LinePort.open(endpoint, "turntable", baudrate, timeout_s, protocol.write_terminator,
                             protocol.read_terminator)
        return cls(line, f"serial {endpoint}", protocol, n_axes)

    # ------------------------------------------------------------------ the Turntable interface
    def identify(self) -> str:
        return self._ask(self.protocol.identify)["identity"]

    def move_to(self, angles_deg: np.ndarray) -> None:
        """Command every axis; limits are the caller's gate (LimitedTurntable)."""
        for axis, angle in enumerate(np.asarray(angles_deg, dtype=float), start=1):
            self._ask(self.protocol.move, axis=axis, angle=float(angle))

    def read_angles_deg(self) -> np.ndarray:
        return np.array([float(self._ask(self.protocol.position, axis=axis)["angle"])
                         for axis in range(1, self.n_axes + 1)])

    def in_position(self) -> bool:
        """Not busy; a controller fault is raised, never waited out."""
        fault = self._ask(self.protocol.fault)["fault"]
        if fault not in self.protocol.fault_ok:
            raise InstrumentError(f"turntable ({self.endpoint}): controller fault {fault}")
        return self._ask(self.protocol.busy)["busy"] not in self.protocol.busy_values

    def stop(self) -> None:
        self._ask(self.protocol.stop)

    def close(self) -> None:
        self._line.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each request on its own (a move of three axes is three requests, each safe to repeat)."""
        self._retry = call

    def reconnect(self) -> None:
        self._line.reconnect()

    # ------------------------------------------------------------------ wire
    def _ask(self, command: Command, **fields: object) -> dict[str, str]:
        return self._retry(lambda: self._ask_once(command, **fields), self.reconnect)

    def _ask_once(self, command: Command, **fields: object) -> dict[str, str]:
        request = command.send.format(**fields)
        reply = self._line.ask(request)
        if self._error.search(reply):
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r} refused: {reply}")
        match = re.fullmatch(command.reply, reply)
        if match is None:
            raise TransientInstrumentError(f"turntable ({self.endpoint}): {request!r}: unexpected reply {reply!r}")
        return {k: v for k, v in match.groupdict().items() if v is not None}


def _open(config: TurntableConfig, endpoint: str) -> SerialTurntable:
    return SerialTurntable.open(endpoint, config.line_protocol(), len(config.axes), config.baudrate, config.timeout_s)


SERIAL = TurntableDriver("serial", _open, simulator="accelcal_rig.sim.turntable_server:serve_line",
                         protocol="accelcal_rig.protocols.turntable_line")
