"""A simulated ADXL355 behind a serial bridge, on a pseudo-terminal: the register map, including the
96-entry FIFO that fills at the output data rate on the shared clock, fed by the lab's sensor model."""

from __future__ import annotations

import math

from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_transport import BRIDGE_GREETING
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer

_READ_ONLY_BELOW = 0x1E  # ID, status, data and FIFO registers
_FIFO_CAPACITY_BYTES = 3 * adxl355.FIFO_CAPACITY_ENTRIES
_SAMPLES_IN_FIFO = adxl355.FIFO_CAPACITY_ENTRIES // 3


class SimulatedAdxl355:
    """One DUT's ADXL355 at register level."""

    def __init__(self, lab: VirtualLab, index: int) -> None:
        self._lab = lab
        self._index = index
        self.reset()

    def reset(self) -> None:
        self._regs = bytearray(0x30)
        self._regs[0:4] = bytes([adxl355.DEVID_AD, adxl355.DEVID_MST, adxl355.PARTID, 0x01])
        self._regs[adxl355.REG_RANGE] = 0x81
        self._regs[adxl355.REG_POWER_CTL] = adxl355.POWER_CTL_STANDBY
        self._regs[adxl355.REG_FIFO_SAMPLES] = 0x60
        self._fifo = bytearray()
        self._overflow = False
        self._next_sample_s: float | None = None

    @property
    def _measuring(self) -> bool:
        return not self._regs[adxl355.REG_POWER_CTL] & adxl355.POWER_CTL_STANDBY

    @property
    def _odr_hz(self) -> float:
        return adxl355.OUTPUT_DATA_RATES_HZ[self._regs[adxl355.REG_FILTER] & 0x0F]

    @property
    def _range_g(self) -> int:
        return {code: g for g, code in adxl355.RANGE_CODES.items()}[self._regs[adxl355.REG_RANGE] & 0x03]

    def read(self, address: int, count: int) -> bytes:
        self._fill_fifo()
        if address == adxl355.REG_FIFO_DATA:  # no auto-increment: a burst drains the FIFO
            taken, self._fifo = bytes(self._fifo[:count]), self._fifo[count:]
            return taken + adxl355.empty_fifo_entries((count - len(taken)) // 3)
        self._regs[adxl355.REG_STATUS] = (
            (adxl355.STATUS_FIFO_OVR if self._overflow else 0)
            | (0x02 if len(self._fifo) >= _FIFO_CAPACITY_BYTES else 0)
            | (adxl355.STATUS_DATA_RDY if self._fifo else 0)
        )
        self._regs[adxl355.REG_FIFO_ENTRIES] = len(self._fifo) // 3
        raw = int(adxl355.raw_from_temperature_c(self._lab.dut_reading_c(self._index)))
        self._regs[adxl355.REG_TEMP2], self._regs[adxl355.REG_TEMP2 + 1] = raw >> 8, raw & 0xFF
        if address <= adxl355.REG_STATUS < address + count:
            self._overflow = False  # reading STATUS clears FIFO_OVR
        return bytes(self._regs[address:address + count])

    def write(self, address: int, value: int) -> None:
        if address == adxl355.REG_RESET:
            if value == adxl355.RESET_CODE:
                self.reset()
            return
        if address < _READ_ONLY_BELOW or address >= len(self._regs):
            raise ValueError(f"register 0x{address:02X} is read-only or does not exist")
        if address in (adxl355.REG_RANGE, adxl355.REG_FILTER) and self._measuring:
            raise ValueError("RANGE and FILTER change only in standby")
        self._fill_fifo()
        was_measuring = self._measuring
        self._regs[address] = value
        if address == adxl355.REG_POWER_CTL and was_measuring != self._measuring:
            self._fifo.clear()  # standby resets the FIFO; measuring starts a fresh one
            self._overflow = False
            self._next_sample_s = self._lab.clock.now() if self._measuring else None

    def _fill_fifo(self) -> None:
        """Add the samples due since the last look; beyond 32 samples the FIFO overflows (oldest lost)."""
        if self._next_sample_s is None:
            return
        now = self._lab.clock.now()
        due = math.floor((now - self._next_sample_s) * self._odr_hz + 1e-9)
        if due <= 0:
            return
        room = _SAMPLES_IN_FIFO - len(self._fifo) // 9
        kept = min(due, _SAMPLES_IN_FIFO)
        t_first = self._next_sample_s + (due - kept) / self._odr_hz
        codes = self._lab.dut_samples(self._index, t_first, kept, self._odr_hz, self._range_g)
        self._fifo += adxl355.encode_fifo(codes)
        if due > room:
            self._overflow = True
            self._fifo = self._fifo[-_FIFO_CAPACITY_BYTES:]
        self._next_sample_s += due / self._odr_hz


class SimulatedBridgeServer:
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ADXL355."""

    def __init__(self, lab: VirtualLab, index: int) -> None:
        self._lab = lab
        self.device = SimulatedAdxl355(lab, index)
        self._server = PtyLineServer(self._handle, b"\n", f"simulated-bridge-{lab.duts[index].serial}")
        self.path = self._server.path

    def start(self) -> SimulatedBridgeServer:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, request: str) -> str:
        parts = request.split()
        try:
            with self._lab.lock:
                if parts == ["?"]:
                    return f"{BRIDGE_GREETING} 1 accelcal-rig simulated bridge"
                if len(parts) == 3 and parts[0] == "R":
                    return "=" + self.device.read(int(parts[1], 16), int(parts[2])).hex().upper()
                if len(parts) == 3 and parts[0] == "W":
                    self.device.write(int(parts[1], 16), int(parts[2], 16))
                    return "="
        except ValueError as exc:
            return f"!{exc}"
        return f"!unknown request {request!r}"
