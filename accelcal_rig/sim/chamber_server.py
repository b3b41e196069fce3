"""A simulated chamber controller on the wire: a pymodbus TCP server on 127.0.0.1 serving a register map.

Any Modbus master can talk to it. Each request is answered from the virtual lab at the shared clock's
time; a set-point, set-point limit or power write goes into the lab. Beside the driver's map it serves the
controller's panel (sim/register_panels.py: what the maker's own library reads and writes). Registers outside
both do not exist (Modbus exception 2), as on a real controller; a value it cannot take (half a float, a NaN or
infinite set point, limits that cross, an output value the map does not name) is exception 3, illegal data
value, and changes nothing.
"""

from __future__ import annotations

import asyncio
import datetime as dt
import math
import struct
import threading

from pymodbus.constants import ExcCodes
from pymodbus.server import ModbusTcpServer
from pymodbus.simulator import DataType, SimData, SimDevice

from accelcal_rig.config.rig import ChamberConfig
from accelcal_rig.protocols.chamber_registers import ChamberRegisterMap, encode_temperature
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.register_panels import PanelRegister, PanelState, panel_for

_STARTUP_TIMEOUT_S = 10.0
#: A dropped request is answered this late (wall clock): after any sane client timeout, to a client that
#: has reconnected by then.
_DROPPED_REPLY_LATE_S = 5.0


class SimulatedChamberServer:
    def __init__(self, lab: VirtualLab, registers: ChamberRegisterMap, device_id: int = 1,
                 host: str = "127.0.0.1", port: int = 0, faults: ReplyFaults | None = None,
                 stall_after_s: float | None = None, panel: tuple[PanelRegister, ...] = ()) -> None:
        self._lab = lab
        owned = {registers.process_value, registers.setpoint, registers.identity_register, registers.decimals_register,
                 registers.units_register, registers.power_register, registers.alarm_register,
                 registers.setpoint_low_register, registers.setpoint_high_register, registers.purge_register}
        #: The panel's registers the map does not use: a rig config that wires a map register (a purge output)
        #: to an address of the panel's (an event) makes it the map's.
        self._panel = {register.address: register for register in panel if register.address not in owned}
        self._panel_state = PanelState(clock_start=dt.datetime.now(dt.UTC).replace(microsecond=0, tzinfo=None))
        self._faults = faults
        self._stall_after_s = stall_after_s
        self._map = registers
        self._device_id = device_id
        self._address = (host, port)
        self._loop = asyncio.new_event_loop()
        self._server: ModbusTcpServer | None = None
        self._thread = threading.Thread(target=self._run, name="simulated-chamber", daemon=True)
        self._ready = threading.Event()
        self._startup_error: BaseException | None = None
        self.host, self.port = host, port
        #: The last set point written over the wire, for tests that check the safe state.
        self.last_setpoint_c: float | None = None

    @property
    def endpoint(self) -> str:
        return f"{self.host}:{self.port}"

    def start(self) -> SimulatedChamberServer:
        self._thread.start()
        if not self._ready.wait(_STARTUP_TIMEOUT_S):
            raise RuntimeError("simulated chamber server did not start")
        if self._startup_error is not None:
            raise self._startup_error
        return self

    def stop(self) -> None:
        if self._server is not None and self._loop.is_running():
            asyncio.run_coroutine_threadsafe(self._shutdown(), self._loop).result(_STARTUP_TIMEOUT_S)
            self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(_STARTUP_TIMEOUT_S)

    async def _shutdown(self) -> None:
        """Stop serving; requests still held back by a fault are dropped for good."""
        assert self._server is not None
        await self._server.shutdown()
        for task in asyncio.all_tasks():
            if task is not asyncio.current_task():
                task.cancel()

    # ------------------------------------------------------------------ server thread
    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._loop.run_until_complete(self._listen())
        except BaseException as exc:  # noqa: BLE001 - handed to start(), which raises it in the caller
            self._startup_error = exc
            self._ready.set()
            return
        self._ready.set()
        self._loop.run_forever()
        self._loop.close()

    async def _listen(self) -> None:
        device = SimDevice(id=self._device_id, simdata=self._blocks(), action=self._action)
        self._server = ModbusTcpServer(device, address=self._address)
        await self._server.serve_forever(background=True)
        self.host, self.port = self._server.transport.sockets[0].getsockname()[:2]  # type: ignore[attr-defined]

    def _blocks(self) -> list[SimData]:
        m = self._map
        width = 2 if m.encoding == "float32" else 1
        addresses = {m.process_value: width, m.setpoint: width}
        for register in (m.setpoint_low_register, m.setpoint_high_register):
            if register is not None:
                addresses[register] = width
        for register in (m.identity_register, m.decimals_register, m.units_register, m.power_register,
                         m.alarm_register, m.purge_register):
            if register is not None:
                addresses[register] = 1
        for panel in self._panel.values():
            addresses.setdefault(panel.address, panel.count)
        return [SimData(address=a, count=n, datatype=DataType.REGISTERS) for a, n in sorted(addresses.items())]

    async def _action(self, function_code: int, start_address: int, address: int, count: int,
                      current_registers: list[int], set_values: list[int] | list[bool] | None) -> ExcCodes | None:
        fault = self._faults.draw(("drop", "delay", "busy", "disconnect")) if self._faults else None
        if fault == "delay":
            await asyncio.sleep(self._faults.faults.delay_s)  # type: ignore[union-attr]
        elif fault == "busy":
            return ExcCodes.DEVICE_BUSY
        answer = self._answer(address, count, start_address, current_registers, set_values)
        if fault == "drop":  # carried out at once, as a controller does; only its reply is lost (sent to nobody)
            await asyncio.sleep(_DROPPED_REPLY_LATE_S)
        return answer

    def _answer(self, address: int, count: int, start_address: int, current_registers: list[int],
                set_values: list[int] | list[bool] | None) -> ExcCodes | None:
        """Carry out a request on the lab now: a write, or the registers read filled in."""
        requested = range(address, address + count)
        with self._lab.lock:
            if set_values is not None:
                return self._write(requested, [int(v) for v in set_values], address)
            for register, words in self._values(requested).items():
                for offset, word in enumerate(words):
                    if register + offset in requested:
                        current_registers[register + offset - start_address] = word
        return None

    def _write(self, requested: range, values: list[int], address: int) -> ExcCodes | None:
        m = self._map
        now = self._lab.clock.now()
        width = 2 if m.encoding == "float32" else 1
        if m.setpoint in requested:
            if m.setpoint + width - 1 not in requested:
                return ExcCodes.ILLEGAL_VALUE  # half a float: real controllers refuse it too
            offset = m.setpoint - address
            setpoint = self._decode(values[offset:offset + width])
            if not math.isfinite(setpoint):
                return ExcCodes.ILLEGAL_VALUE  # a NaN or infinite float: refused, the set point kept
            if m.setpoint_low_register is not None:  # a controller with limits clamps to them, silently
                low, high = self._lab.controller_limits_c
                setpoint = min(max(setpoint, low), high)
            if self._stall_after_s is None or now < self._stall_after_s:
                self._lab.thermal.set_setpoint(now, setpoint)  # a stalled chamber takes it but does not follow
            self.last_setpoint_c = setpoint
        refused = self._write_limits(requested, values, address)
        if refused is not None:
            return refused
        for panel in self._panel.values():
            if panel.address in requested:
                words = values[panel.address - address:panel.address - address + panel.count]
                if panel.write is None:
                    return ExcCodes.ILLEGAL_ADDRESS
                if len(words) < panel.count or not panel.write(self._panel_state, self._lab, words):
                    return ExcCodes.ILLEGAL_VALUE
        if m.power_register is not None and m.power_register in requested:
            value = values[m.power_register - address]
            if value not in (m.power_on, m.power_off):
                return ExcCodes.ILLEGAL_VALUE
            self._lab.thermal.set_power(now, value == m.power_on)
        if m.purge_register is not None and m.purge_register in requested:
            value = values[m.purge_register - address]
            if value not in (m.purge_on, m.purge_off):
                return ExcCodes.ILLEGAL_VALUE
            self._lab.moisture.set_purge(now, value == m.purge_on)
        return None

    def _write_limits(self, requested: range, values: list[int], address: int) -> ExcCodes | None:
        """The controller's set point limits, written as ESPEC's library's set_loop_range writes them (high, then
        low): limits that would cross, or are not finite, are refused and kept."""
        m = self._map
        width = 2 if m.encoding == "float32" else 1
        low, high = self._lab.controller_limits_c
        for register, is_low in ((m.setpoint_low_register, True), (m.setpoint_high_register, False)):
            if register is None or register not in requested:
                continue
            words = values[register - address:register - address + width]
            if len(words) < width:
                return ExcCodes.ILLEGAL_VALUE
            value = self._decode(words)
            if not math.isfinite(value):
                return ExcCodes.ILLEGAL_VALUE
            low, high = (value, high) if is_low else (low, value)
        if low >= high:
            return ExcCodes.ILLEGAL_VALUE
        self._lab.controller_limits_c = (low, high)
        return None

    def _values(self, requested: range) -> dict[int, list[int]]:
        """The map's registers; the process value is measured only when asked for (it draws noise)."""
        m = self._map
        shown = self.last_setpoint_c if self.last_setpoint_c is not None else self._lab.thermal.setpoint_c
        values = {m.setpoint: self._encode(shown)}
        if not set(requested).isdisjoint((m.process_value, m.process_value + 1)):
            values[m.process_value] = self._encode(self._lab.chamber_reading_c())
        if m.identity_register is not None and m.identity_value is not None:
            values[m.identity_register] = [m.identity_value]
        if m.decimals_register is not None:
            values[m.decimals_register] = [m.decimals]
        if m.units_register is not None:
            values[m.units_register] = [m.units_celsius]
        if m.power_register is not None:
            values[m.power_register] = [m.power_on if self._lab.thermal.powered else m.power_off]
        if m.alarm_register is not None:
            values[m.alarm_register] = [m.alarm_inactive[0]]
        if m.purge_register is not None:
            values[m.purge_register] = [m.purge_on if self._lab.moisture.purge_on else m.purge_off]
        if m.setpoint_low_register is not None and m.setpoint_high_register is not None:
            low, high = self._lab.controller_limits_c
            values[m.setpoint_low_register], values[m.setpoint_high_register] = self._encode(low), self._encode(high)
        for panel in self._panel.values():
            if not set(requested).isdisjoint(range(panel.address, panel.address + panel.count)):
                values.setdefault(panel.address, panel.read(self._panel_state, self._lab))
        return values

    def _encode(self, temperature_c: float) -> list[int]:
        return encode_temperature(self._map, temperature_c)

    def _decode(self, words: list[int]) -> float:
        m = self._map
        if m.encoding == "float32":
            high, low = (words[1], words[0]) if m.word_order == "little" else (words[0], words[1])
            return struct.unpack(">f", struct.pack(">HH", high, low))[0]
        return struct.unpack(">h", struct.pack(">H", words[0]))[0] / 10**m.decimals


def serve_modbus(lab: VirtualLab, config: ChamberConfig, faults: InstrumentFaults) -> SimulatedChamberServer:
    """The Modbus chamber drivers' simulator: the config's register map on Modbus TCP (RTU too)."""
    registers = config.register_map()
    return SimulatedChamberServer(lab, registers, config.device_id, faults=faults.replies,
                                  stall_after_s=faults.after_s(faults.settings.chamber_stall_after_min),
                                  panel=panel_for(config.profile, registers))
