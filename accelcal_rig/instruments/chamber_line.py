"""Thermal chamber controller speaking an ASCII line protocol (a profile of accelcal_rig.protocols.chamber_lines),
over TCP (`host:port`) or a serial line (a device path or any pyserial URL).

Every failure is one line naming the chamber and its endpoint: a refusal (the profile's error replies,
with their meaning: a controller whose panel locks remote writes says so), a garbled or unexpected reply (transient: asked
again), silence, a controller not in °C, or values no chamber reads.
"""

from __future__ import annotations

import re
from typing import Self

from accelcal_rig.config.rig import ChamberConfig, is_host_port
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.definitions import ChamberDriver
from accelcal_rig.instruments.limits import plausible_c, refuse_non_finite
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.instruments.retrying import RetryCall
from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol, Operation


class LineChamber:
    """A chamber of exactly the capabilities its profile has (an alarm query, its own limits, humidity, a purge
    output, a set point to decimals: accelcal_rig.instruments.capabilities), whichever way it is made."""

    def __new__(cls, line: LinePort, endpoint: str, protocol: ChamberLineProtocol) -> Self:
        return instance_of(composed(cls, _capabilities(protocol)) if cls is LineChamber else cls)

    def __init__(self, line: LinePort, endpoint: str, protocol: ChamberLineProtocol) -> None:
        self._line = line
        self.endpoint = endpoint
        self.protocol = protocol
        self._retry: RetryCall = lambda operation, reconnect: operation()

    @classmethod
    def open(cls, endpoint: str, protocol: ChamberLineProtocol, baudrate: int = 9600,
             timeout_s: float = 1.0) -> LineChamber:
        """`host:port` is TCP; anything else a serial device or pyserial URL."""
        url = f"socket://{endpoint}" if is_host_port(endpoint) else endpoint
        line = LinePort.open(url, "chamber", baudrate, timeout_s, protocol.write_terminator, protocol.read_terminator,
                             protocol.encoding)
        where = f"tcp {endpoint}" if is_host_port(endpoint) else f"serial {endpoint}"
        return cls(line, where, protocol)

    # ------------------------------------------------------------------ the Chamber interface
    def identify(self) -> str:
        """Refuse a controller not in °C (where the profile can ask); describe it."""
        identity = self._ask("identify")["identity"]
        if self.protocol.units is not None:
            units = self._ask("units")["units"]
            if units != self.protocol.units_celsius:
                raise self._failure(f"controller is not in °C (units read {units!r}, expected "
                                    f"{self.protocol.units_celsius!r})")
        temperature, setpoint = self.read_temperature_c(), self.read_setpoint_c()
        return f"{identity} (PV {temperature:.1f} °C, SP {setpoint:.1f} °C)"

    def read_temperature_c(self) -> float:
        return self._temperature("read_temperature", "pv", "process value")

    def read_setpoint_c(self) -> float:
        return self._temperature("read_setpoint", "sp", "set point")

    def write_setpoint_c(self, setpoint_c: float) -> None:
        """Limits are the caller's gate (LimitedChamber), which also reads the set point back; a NaN is refused
        here too (`TEMP, Snan` would reach the controller)."""
        refuse_non_finite(f"chamber ({self.endpoint})", "setpoint", setpoint_c, " °C")
        self._ask("write_setpoint", value=float(setpoint_c))

    def set_power(self, on: bool) -> None:
        if self.protocol.power_on is None:
            raise self._failure("the protocol profile has no power command")
        self._ask("power_on" if on else "power_off")

    def close(self) -> None:
        self._line.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each request on its own (queries, and set points and outputs as absolute values, repeat safely)."""
        self._retry = call

    def reconnect(self) -> None:
        self._line.reconnect()

    # ------------------------------------------------------------------ values
    def _temperature(self, operation: Operation, group: str, what: str) -> float:
        value = float(self._ask(operation)[group])
        if not plausible_c(value):
            raise self._failure(f"{what} reads {value:g} °C: not a chamber's air (wrong profile or units?)")
        return value

    def _failure(self, message: str) -> InstrumentError:
        return InstrumentError(f"chamber ({self.endpoint}): {message}")

    # ------------------------------------------------------------------ wire
    def _ask(self, operation: Operation, **fields: object) -> dict[str, str]:
        return self._retry(lambda: self._ask_once(operation, **fields), self.reconnect)

    def _ask_once(self, operation: Operation, **fields: object) -> dict[str, str]:
        command = self.protocol.command(operation)
        request = self.protocol.request(operation, **fields)
        if command is None or command.reply is None:
            self._line.send(request)
            return {}
        return read_reply(self.protocol, operation, request, self._line.ask(request), self.endpoint)


def read_reply(protocol: ChamberLineProtocol, operation: Operation, request: str, reply: str,
               endpoint: str) -> dict[str, str]:
    """A reply to an operation's request, as the driver reads it: a refusal (the profile's error pattern, with
    what its code means) is an InstrumentError; a reply that does not match the command's pattern in full
    is transient (garbled: asked again); else the values its named groups carry."""
    command = protocol.command(operation)
    assert command is not None and command.reply is not None  # only an answered command has a reply to read
    refusal = re.search(protocol.error_pattern, reply)
    if refusal is not None:
        code = refusal.groupdict().get("code")
        meaning = protocol.errors.get(code.strip()) if code else None
        raise InstrumentError(f"chamber ({endpoint}): {request!r} refused: {reply!r}"
                              + (f" ({meaning})" if meaning else ""))
    match = re.fullmatch(command.reply, reply)
    if match is None:
        raise TransientInstrumentError(f"chamber ({endpoint}): {request!r}: unexpected reply {reply!r}")
    return {k: v for k, v in match.groupdict().items() if v is not None}


class _Alarm(LineChamber):
    def alarm_active(self) -> bool:
        """The profile's list of quiet replies, or its alarm bits of a status integer (SIMSERV's 8)."""
        alarm = self._ask("alarm")["alarm"]
        try:
            return self.protocol.alarm_means_active(alarm)
        except ValueError:
            raise self._failure(f"alarm status {alarm!r} is not an integer (the profile reads alarm_bits of it)") \
                from None


class _Limits(LineChamber):
    def controller_limits_c(self) -> tuple[float, float] | None:
        low = self._temperature("read_low_limit", "low", "set point low limit")
        high = self._temperature("read_high_limit", "high", "set point high limit")
        if not low < high:
            raise self._failure(f"set point limits read {low:g}…{high:g} °C: not a range")
        return low, high


class _Humidity(LineChamber):
    def read_humidity_pct(self) -> float | None:
        """The controller's relative humidity reading."""
        value = float(self._ask("humidity")["humidity"])
        if not 0.0 <= value <= 100.5:
            raise self._failure(f"relative humidity reads {value:g} %: not a reading (wrong profile?)")
        return value


class _Purge(LineChamber):
    def set_purge(self, on: bool) -> None:
        """Switch the dry-air purge output (frost and condensation on a cold fixture)."""
        self._ask("purge_on" if on else "purge_off")


class _Resolution(LineChamber):
    @property
    def setpoint_decimals(self) -> int:
        """The decimals the profile writes a set point with: the limit gate rounds to them first."""
        decimals = self.protocol.setpoint_decimals
        assert decimals is not None  # only a profile that writes to decimals has this capability
        return decimals


def _capabilities(protocol: ChamberLineProtocol) -> list[type[LineChamber]]:
    """What a profile's commands let its chamber do beyond the core."""
    offered = {_Alarm: protocol.alarm, _Limits: protocol.read_low_limit, _Humidity: protocol.humidity,
               _Purge: protocol.purge_on, _Resolution: protocol.setpoint_decimals}
    return [mixin for mixin, present in offered.items() if present is not None]


def _open(config: ChamberConfig, endpoint: str) -> LineChamber:
    return LineChamber.open(endpoint, config.line_protocol(), config.baudrate, config.timeout_s)


LINE = ChamberDriver("line", _open, simulator="accelcal_rig.sim.chamber_line_server:serve_line",
                     protocol="accelcal_rig.protocols.chamber_lines")
