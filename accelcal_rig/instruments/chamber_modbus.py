"""Thermal chamber controller over Modbus (pymodbus): TCP, or RTU on a serial port or pyserial URL.

Every failure becomes an InstrumentError naming the chamber and its endpoint: a refused connection,
a missing reply, a Modbus exception (a register the controller does not have: a wrong map), an identity,
decimals or units register that disagrees with the map, or values no chamber reads.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Self

import numpy as np
from pymodbus.client import ModbusSerialClient, ModbusTcpClient
from pymodbus.client.base import ModbusBaseSyncClient
from pymodbus.exceptions import ModbusException

from accelcal_rig.config.rig import ChamberConfig
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.definitions import ChamberDriver
from accelcal_rig.instruments.limits import plausible_c, refuse_non_finite
from accelcal_rig.instruments.retrying import RetryCall
from accelcal_rig.protocols.chamber_registers import ChamberRegisterMap

#: Modbus exception codes that mean "try again": 5 acknowledge (still working), 6 server device busy.
_BUSY_CODES = (5, 6)


class ModbusChamber:
    """A chamber of exactly the capabilities its register map has (an alarm register, limit registers, a purge
    output, a scaled set point: accelcal_rig.instruments.capabilities), whichever way it is made."""

    def __new__(cls, client: ModbusBaseSyncClient, endpoint: str, registers: ChamberRegisterMap,
                device_id: int = 1) -> Self:
        return instance_of(composed(cls, _capabilities(registers)) if cls is ModbusChamber else cls)

    def __init__(self, client: ModbusBaseSyncClient, endpoint: str, registers: ChamberRegisterMap,
                 device_id: int = 1) -> None:
        self._client = client
        self._retry: RetryCall = lambda operation, reconnect: operation()
        self.endpoint = endpoint
        self.registers = registers
        self.device_id = device_id

    @classmethod
    def tcp(cls, host: str, port: int, registers: ChamberRegisterMap, device_id: int = 1,
            timeout_s: float = 1.0) -> ModbusChamber:
        client = ModbusTcpClient(host, port=port, timeout=timeout_s, retries=0)
        return cls._connected(client, f"modbus-tcp {host}:{port}", registers, device_id)

    @classmethod
    def rtu(cls, port: str, registers: ChamberRegisterMap, device_id: int = 1, baudrate: int = 9600,
            parity: str = "N", stopbits: int = 1, timeout_s: float = 1.0) -> ModbusChamber:
        client = ModbusSerialClient(port, baudrate=baudrate, parity=parity, stopbits=stopbits, timeout=timeout_s,
                                    retries=0)
        return cls._connected(client, f"modbus-rtu {port}", registers, device_id)

    @classmethod
    def _connected(cls, client: ModbusBaseSyncClient, endpoint: str, registers: ChamberRegisterMap,
                   device_id: int) -> ModbusChamber:
        if not client.connect():
            raise InstrumentError(f"chamber ({endpoint}): cannot connect (is it on, the address right, the port free?)")
        return cls(client, endpoint, registers, device_id)

    # ------------------------------------------------------------------ the Chamber interface
    def identify(self) -> str:
        """Check the controller is the one the map describes; describe it."""
        m = self.registers
        if m.identity_register is not None and m.identity_value is not None:
            found = self._read(m.identity_register, 1)[0]
            if found != m.identity_value:
                raise self._error(f"register {m.identity_register} reads {found}, the map expects model "
                                  f"{m.identity_value}: wrong register map or controller")
        if m.decimals_register is not None:
            found = self._read(m.decimals_register, 1)[0]
            if found != m.decimals:
                raise self._error(f"controller shows {found} decimal places (register {m.decimals_register}), "
                                  f"the map expects {m.decimals}")
        if m.units_register is not None:
            found = self._read(m.units_register, 1)[0]
            if found != m.units_celsius:
                raise self._error(f"controller is not in °C (register {m.units_register} reads {found})")
        temperature, setpoint = self.read_temperature_c(), self.read_setpoint_c()
        model = f"model {m.identity_value}, " if m.identity_value is not None else ""
        return f"{m.encoding} controller ({model}PV {temperature:.1f} °C, SP {setpoint:.1f} °C)"

    def read_temperature_c(self) -> float:
        return self._plausible(self._read_temperature(self.registers.process_value), "process value")

    def read_setpoint_c(self) -> float:
        return self._plausible(self._read_temperature(self.registers.setpoint), "set point")

    def write_setpoint_c(self, setpoint_c: float) -> None:
        """Write the static set point (both float words in one request). Limits are the caller's gate; a NaN
        is refused here too (it encodes as a float32 NaN, and fails round() as a scaled integer)."""
        refuse_non_finite(f"chamber ({self.endpoint})", "setpoint", setpoint_c, " °C")
        self._write(self.registers.setpoint, self._encode(setpoint_c))

    def set_power(self, on: bool) -> None:
        m = self.registers
        if m.power_register is None:
            raise self._error("the register map has no power event")
        self._write(m.power_register, [m.power_on if on else m.power_off])

    def close(self) -> None:
        self._client.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each Modbus request on its own (reads, and writes of absolute values, are safe to repeat)."""
        self._retry = call

    def reconnect(self) -> None:
        self._client.close()
        if not self._client.connect():
            raise TransientInstrumentError(f"chamber ({self.endpoint}): cannot connect", reconnect=True)

    # ------------------------------------------------------------------ encoding
    def _read_temperature(self, address: int) -> float:
        m = self.registers
        if m.encoding == "float32":
            words = self._read(address, 2)
            return _number(self._client.convert_from_registers(words, self._client.DATATYPE.FLOAT32,
                                                               word_order=m.word_order))
        raw = self._client.convert_from_registers(self._read(address, 1), self._client.DATATYPE.INT16)
        return _number(raw) / 10**m.decimals

    def _encode(self, temperature_c: float) -> list[int]:
        m = self.registers
        if m.encoding == "float32":
            return self._client.convert_to_registers(float(temperature_c), self._client.DATATYPE.FLOAT32,
                                                     word_order=m.word_order)
        scaled = round(temperature_c * 10**m.decimals)
        if not -32768 <= scaled <= 32767:
            raise self._error(f"{temperature_c:g} °C does not fit a 16-bit register at {m.decimals} decimals")
        return self._client.convert_to_registers(scaled, self._client.DATATYPE.INT16)

    def _plausible(self, value: float, what: str) -> float:
        """Swapped float words give NaN, huge values or, for round temperatures (zero low word), denormals."""
        if denormal_float32(value) or not plausible_c(value):
            raise self._error(f"{what} reads {value:g} °C: wrong register map or word order")
        return value

    # ------------------------------------------------------------------ wire
    def _read(self, address: int, count: int) -> list[int]:
        return self._retry(lambda: self._read_once(address, count), self.reconnect)

    def _write(self, address: int, values: list[int]) -> None:
        self._retry(lambda: self._write_once(address, values), self.reconnect)

    def _read_once(self, address: int, count: int) -> list[int]:
        reply = self._exchange(f"reading register {address}", f"register {address} refused ({{}}): wrong register map?",
                               lambda: self._client.read_holding_registers(address, count=count,
                                                                           device_id=self.device_id))
        return list(reply.registers)

    def _write_once(self, address: int, values: list[int]) -> None:
        self._exchange(f"writing register {address}", f"write to register {address} refused ({{}})",
                       lambda: self._client.write_registers(address, values, device_id=self.device_id))

    def _exchange(self, what: str, refused: str, request: Callable[[], Any]) -> Any:
        """One Modbus request: no reply is transient (reconnect), busy is transient, any other exception
        response is a refusal (`refused`, with `{}` for the response)."""
        try:
            reply = request()
        except ModbusException as exc:
            raise self._lost(f"no reply {what}: {exc}") from None
        if reply.isError():
            if getattr(reply, "exception_code", None) in _BUSY_CODES:
                raise TransientInstrumentError(f"chamber ({self.endpoint}): busy {what} ({reply})")
            raise self._error(refused.format(reply))
        return reply

    def _lost(self, message: str) -> TransientInstrumentError:
        return TransientInstrumentError(f"chamber ({self.endpoint}): {message}", reconnect=True)

    def _error(self, message: str) -> InstrumentError:
        return InstrumentError(f"chamber ({self.endpoint}): {message}")


class _Alarm(ModbusChamber):
    def alarm_active(self) -> bool:
        m = self.registers
        assert m.alarm_register is not None  # only a map with an alarm register has this capability
        return self._read(m.alarm_register, 1)[0] not in m.alarm_inactive


class _Limits(ModbusChamber):
    def controller_limits_c(self) -> tuple[float, float] | None:
        m = self.registers
        assert m.setpoint_low_register is not None and m.setpoint_high_register is not None
        low = self._plausible(self._read_temperature(m.setpoint_low_register), "set point low limit")
        high = self._plausible(self._read_temperature(m.setpoint_high_register), "set point high limit")
        if not low < high:
            raise self._error(f"set point limits read {low:g}…{high:g} °C (registers {m.setpoint_low_register}/"
                              f"{m.setpoint_high_register}): not a range")
        return low, high


class _Purge(ModbusChamber):
    def set_purge(self, on: bool) -> None:
        m = self.registers
        assert m.purge_register is not None  # only a map with a purge output has this capability
        self._write(m.purge_register, [m.purge_on if on else m.purge_off])


class _Resolution(ModbusChamber):
    @property
    def setpoint_decimals(self) -> int:
        """A scaled register holds the set point to its decimals (the limit gate rounds to them first)."""
        return self.registers.decimals


def _capabilities(m: ChamberRegisterMap) -> list[type[ModbusChamber]]:
    """What a register map lets its chamber do beyond the core."""
    offered = {_Alarm: m.alarm_register is not None,
               _Limits: m.setpoint_low_register is not None and m.setpoint_high_register is not None,
               _Purge: m.purge_register is not None, _Resolution: m.encoding == "scaled-int16"}
    return [mixin for mixin, present in offered.items() if present]


def _number(value: object) -> float:
    """A single register value as pymodbus converts it (typed as any of its conversions' results)."""
    if not isinstance(value, int | float):
        raise TypeError(f"expected one number from the register conversion, got {value!r}")
    return float(value)


def _open_tcp(config: ChamberConfig, endpoint: str) -> ModbusChamber:
    host, _, port = endpoint.rpartition(":")
    if not host or not port.isdigit():
        raise InstrumentError(f"chamber (modbus-tcp {endpoint}): endpoint is not host:port")
    return ModbusChamber.tcp(host, int(port), config.register_map(), config.device_id, config.timeout_s)


def _open_rtu(config: ChamberConfig, endpoint: str) -> ModbusChamber:
    return ModbusChamber.rtu(endpoint, config.register_map(), config.device_id, config.baudrate, config.parity,
                             config.stopbits, config.timeout_s)


MODBUS_TCP = ChamberDriver("modbus-tcp", _open_tcp, simulator="accelcal_rig.sim.chamber_server:serve_modbus",
                           protocol="accelcal_rig.protocols.chamber_registers")
#: Simulated on Modbus TCP: the same register map and requests, another framing.
MODBUS_RTU = ChamberDriver("modbus-rtu", _open_rtu, simulator="accelcal_rig.sim.chamber_server:serve_modbus",
                           protocol="accelcal_rig.protocols.chamber_registers", simulated_by="modbus-tcp")


def denormal_float32(value: float) -> bool:
    """A float32 below the smallest normal one (1.18e-38) but not zero: what a round temperature's words read in
    the wrong order give (its zero word becomes the exponent's). A chamber near 0 °C reads a small normal float
    (7.5e-7 °C is one), never a denormal."""
    return value != 0.0 and abs(value) < float(np.finfo(np.float32).tiny)
