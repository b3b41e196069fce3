"""Turntable driver for a line protocol over pyserial (a device path or any pyserial URL)."""

from __future__ import annotations

import re

import numpy as np
import serial

from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.turntable_protocol import Command, TurntableProtocol


class SerialTurntable:
    def __init__(self, port: serial.SerialBase, endpoint: str, protocol: TurntableProtocol, n_axes: int) -> None:
        self._port = port
        self.endpoint = endpoint
        self.protocol = protocol
        self.n_axes = n_axes
        self._error = re.compile(protocol.error_pattern)

    @classmethod
    def open(cls, endpoint: str, protocol: TurntableProtocol, n_axes: int, baudrate: int = 9600,
             timeout_s: float = 2.0) -> SerialTurntable:
        try:
            port = serial.serial_for_url(endpoint, baudrate=baudrate, timeout=timeout_s, write_timeout=timeout_s)
        except (serial.SerialException, ValueError) as exc:
            raise InstrumentError(f"turntable (serial {endpoint}): cannot open: {exc}") from None
        return cls(port, f"serial {endpoint}", protocol, n_axes)

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

    def home(self) -> None:
        self._ask(self.protocol.home)

    def close(self) -> None:
        self._port.close()

    # ------------------------------------------------------------------ wire
    def _ask(self, command: Command, **fields: object) -> dict[str, str]:
        request = command.send.format(**fields)
        terminator = self.protocol.read_terminator.encode()
        try:
            self._port.reset_input_buffer()  # a late reply to an earlier, timed-out request is stale
            self._port.write((request + self.protocol.write_terminator).encode())
            raw = self._port.read_until(terminator)
        except (serial.SerialException, OSError) as exc:
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r}: port failed: {exc}") from None
        if not raw.endswith(terminator):
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r}: no reply within the timeout")
        reply = raw[: -len(terminator)].decode(errors="replace").strip()
        if self._error.search(reply):
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r} refused: {reply}")
        match = re.fullmatch(command.reply, reply)
        if match is None:
            raise InstrumentError(f"turntable ({self.endpoint}): {request!r}: unexpected reply {reply!r}")
        return {k: v for k, v in match.groupdict().items() if v is not None}
