"""A simulated ICM-42688-P at register level (user bank 0): WHO_AM_I, soft reset and RESET_DONE, the two
CONFIG0 registers, PWR_MGMT0, data registers that hold the newest sample of both sensors at the output data rate
on the shared clock, made from the lab's hidden truth of each (DATA_RDY set by a new sample, cleared by reading
INT_STATUS), and the FIFO: 16-byte packets (packet 3) of both sensors, a count, a read port, a flush, and a full
FIFO that drops new samples and sets FIFO_FULL. The bridge's own capture (`C`, `G`) drains it as the reference
firmware does. Register facts: `instruments/icm42688.py`, shared with the driver.

Simplifications (not claims about the chip), the same as the reference firmware's C model of the part
(firmware/host/icm42688_model.h): only bank 0 is modelled (in another bank every register but REG_BANK_SEL reads 0
and ignores writes); a read-only register ignores a write; TEMP_DATA reads the DUT's temperature whatever the power
mode; a sensor off reads DATA_INVALID (-32768) in its data registers; the first sample comes one period after
PWR_MGMT0 turns the sensors on; both sensors sample at ACCEL_CONFIG0's rate, whose code may be one the part's
table does not offer (a low-power rate, or the reserved 0: taken as 1 kHz); a reserved accelerometer FS_SEL (4…7)
is ±16 g. The FIFO: filled only while both sensors measure, FIFO_CONFIG is not bypass and FIFO_CONFIG1 enables
the accelerometer and the gyroscope (not HIRES), always in packet 3, its temperature TEMP_DATA's reading when the
packet is made in the packet's 8 bits (INTF_CONFIG0 only at its reset setting: counts in bytes, big-endian);
it holds 128 packets; stop-on-full drops new samples, stream mode (whose overflow the data sheet does not
describe) drops the oldest; an empty FIFO reads 0xFF (FIFO_DATA's reset value; the data sheet says only that
header bit 7 means empty), and so does FIFO_DATA within a burst from below it; a packet's timestamp is sample
k's time since the sensors came on, (k + 1) periods, in ticks of 32/30 µs (the data sheet's ×32/30 for the
internal clock), its low 16 bits — as the reference firmware's C model of the part makes them.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.sim.bridge_capture import CaptureBuffer
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.sample_ticks import SampleTicks

_DATA = range(regs.REG_TEMP_DATA1, regs.REG_GYRO_DATA_Z0 + 1)
#: The sensors' data registers (a read of TEMP_DATA alone makes no sample).
_SENSOR_DATA = range(regs.REG_ACCEL_DATA_X1, regs.REG_GYRO_DATA_Z0 + 1)
#: Registers whose read looks at the newest samples (data, INT_STATUS, the FIFO's count and port).
_SAMPLED = frozenset({*_DATA, regs.REG_INT_STATUS, regs.REG_FIFO_COUNTH, regs.REG_FIFO_COUNTH + 1, regs.REG_FIFO_DATA})
#: Reset values (data sheet register map): both CONFIG0 registers FS_SEL 0, ODR code 6 (1 kHz).
_CONFIG0_RESET = 0x06
#: ODR codes beyond the low-noise rates the part offers: the accelerometer's low-power rates (codes 12…14), and
#: the reserved code 0 taken as 1 kHz (the C model's choice).
_OTHER_ODR_HZ = {0: 1000.0, 12: 6.25, 13: 3.125, 14: 1.5625}
#: The accelerometer's reserved FS_SEL codes (4…7) taken as ±16 g (FS_SEL 0).
_ACCEL_FS_SEL_RESERVED = 4
#: FIFO_CONFIG1's sensor bits: accelerometer (bit 0), gyroscope (bit 1).
_FIFO_SENSORS = 0x03
#: Samples the bridge's capture buffer holds: its 36 kB (the reference firmware's) in 16-byte packets.
CAPTURE_CAPACITY_SAMPLES = 36864 // regs.PACKET_BYTES


class SimulatedIcm42688:
    """One DUT's ICM-42688-P, fed by the lab's truth of its accelerometer and gyroscope."""

    def __init__(self, lab: VirtualLab, index: int, wrong_who_am_i: bool = False) -> None:
        self._lab = lab
        self._index = index
        self._part = lab.duts[index].part
        self._who_am_i = (self._part.identity[0] ^ 0x07) if wrong_who_am_i else self._part.identity[0]
        self.reset()

    def reset(self) -> None:
        self._regs = bytearray(0x80)
        self._regs[regs.REG_WHO_AM_I] = self._who_am_i
        self._regs[regs.REG_GYRO_CONFIG0] = self._regs[regs.REG_ACCEL_CONFIG0] = _CONFIG0_RESET
        self._regs[regs.REG_INT_STATUS] = regs.INT_STATUS_RESET_DONE
        self._regs[regs.REG_INTF_CONFIG0] = regs.INTF_CONFIG0_RESET
        self._regs[regs.REG_FIFO_DATA] = 0xFF
        self._ticks = SampleTicks()
        self._sample = self._invalid()
        self._newest_s: float | None = None  # the newest sample's time, its registers made when first read
        self._data_due = False
        self._fifo = bytearray()
        self._fifo_pending: list[tuple[float, int]] = []  # (first sample's time, count) runs not yet made
        self._capture = CaptureBuffer(regs.PACKET_BYTES)

    # ------------------------------------------------------------------ what the bridge asks of its part
    @property
    def measuring(self) -> bool:
        """Both sensors in low-noise mode (what the safe state must leave False)."""
        mode = self._regs[regs.REG_PWR_MGMT0]
        return (mode & 0x03) == 0x03 and (mode >> 2 & 0x03) == 0x03

    @property
    def lab(self) -> VirtualLab:
        return self._lab

    @property
    def fifo_packets(self) -> bool:
        """Whether the FIFO is on and filled with packets of both sensors (what the bridge's capture drains)."""
        config1 = self._regs[regs.REG_FIFO_CONFIG1]
        return bool(self._regs[regs.REG_FIFO_CONFIG] & 0xC0) and (config1 & 0x13) == _FIFO_SENSORS

    @property
    def capturing(self) -> bool:
        self._advance()
        return self._capture.left > 0

    @property
    def captured_samples(self) -> int:
        self._advance()
        return self._capture.samples

    def start_capture(self, n_samples: int) -> int:
        """The bridge flushes the FIFO and captures the next `n_samples` packets itself; returns TEMP_DATA as it
        starts. The bridge has checked the part measures with the FIFO in packets (sim/bridge_capture.py)."""
        self._advance()
        self._flush()
        self._capture.start(n_samples)
        return self._temperature_raw()

    def stop_capture(self) -> None:
        """The bridge ends its capture early (a write changed the stream): samples go to the FIFO again."""
        self._advance()
        self._capture.stop()

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        """(the captured packets from index `first` on, TEMP_DATA at the end once complete)."""
        self._advance()
        return self._capture.fetch(first)

    # ------------------------------------------------------------------ registers
    def read(self, address: int, count: int) -> bytes:
        """`count` registers from `address` on, within the map (the bridge refuses a burst past it); a burst from
        FIFO_DATA reads the FIFO, packet after packet."""
        if self._bank:
            span = range(address, address + count)
            return bytes(self._regs[regs.REG_BANK_SEL] if reg == regs.REG_BANK_SEL else 0 for reg in span)
        if address == regs.REG_FIFO_DATA:
            self._advance()
            return self._take_fifo(count)
        span = range(address, address + count)
        if _SAMPLED.isdisjoint(span):
            return bytes(self._regs[address:address + count])
        self._advance()
        if not set(span).isdisjoint(_SENSOR_DATA):
            self._make_data()
        self._regs[regs.REG_TEMP_DATA1:regs.REG_TEMP_DATA1 + 2] = self._temperature_raw().to_bytes(2, "big", signed=True)
        self._regs[regs.REG_ACCEL_DATA_X1:regs.REG_GYRO_DATA_Z0 + 1] = self._sample[2:]
        fifo_bytes = len(self._fifo) + regs.PACKET_BYTES * sum(n for _, n in self._fifo_pending)
        self._regs[regs.REG_FIFO_COUNTH:regs.REG_FIFO_COUNTH + 2] = fifo_bytes.to_bytes(2, "big")
        value = bytes(self._regs[address:address + count])
        if regs.REG_INT_STATUS in span:
            self._regs[regs.REG_INT_STATUS] = 0  # clear on read
        return value

    def write(self, address: int, value: int) -> None:
        """What the part does with a write: a read-only register, or any but REG_BANK_SEL in another bank, ignores
        it; DEVICE_CONFIG's SOFT_RESET resets every register; SIGNAL_PATH_RESET's FIFO_FLUSH empties the FIFO (the
        register reads 0: its bits clear themselves)."""
        if (self._bank and address != regs.REG_BANK_SEL) or address in regs.READ_ONLY_REGISTERS:
            return
        if address == regs.REG_DEVICE_CONFIG and value & regs.DEVICE_CONFIG_SOFT_RESET:
            self.reset()
            return
        self._advance()
        if address == regs.REG_SIGNAL_PATH_RESET:
            if value & regs.SIGNAL_PATH_RESET_FIFO_FLUSH:
                self._flush()
            return
        was_on = self.measuring
        self._regs[address] = value
        if address == regs.REG_PWR_MGMT0 and was_on != self.measuring:
            if self.measuring:
                self._ticks.start(self._lab.clock.now())
            else:
                self._ticks.stop()
            self._sample, self._newest_s = self._invalid(), None
            self._capture.stop()
        elif address in (regs.REG_GYRO_CONFIG0, regs.REG_ACCEL_CONFIG0):
            self._ticks.restart(self._lab.clock.now())

    # ------------------------------------------------------------------ samples
    @property
    def _odr_hz(self) -> float:
        code = regs.split_config0(self._regs[regs.REG_ACCEL_CONFIG0])[1]
        rate = self._part.odr_for_code(code)
        return rate if rate is not None else _OTHER_ODR_HZ[code]

    @property
    def _bank(self) -> int:
        return self._regs[regs.REG_BANK_SEL] & 0x07

    def _range(self, channel: str, register: int) -> float:
        fs_sel = regs.split_config0(self._regs[register])[0]
        if channel == "accel" and fs_sel >= _ACCEL_FS_SEL_RESERVED:
            fs_sel = 0
        return {code: r for r, code in self._part.channel(channel).range_codes.items()}[fs_sel]

    def _advance(self) -> None:
        """Account for the samples due by the clock: the newest in the data registers (DATA_RDY set), each to a
        capture under way, else to the FIFO where it is on (made only when read: a sample nobody reads costs
        nothing)."""
        odr = self._odr_hz if self._ticks.running else 0.0
        newest = self._ticks.newest(self._lab.clock.now(), odr)
        if newest is None:
            return
        self._newest_s, came = newest
        self._data_due = True
        self._regs[regs.REG_INT_STATUS] |= regs.INT_STATUS_DATA_RDY
        first_s = self._newest_s - (came - 1) / odr
        if self._capture.left > 0:
            taken = min(came, self._capture.left)
            self._capture.take(self._packets(first_s, taken, odr), taken, self._temperature_raw)
            first_s, came = first_s + taken / odr, came - taken
        if came > 0 and self.fifo_packets:
            self._to_fifo(first_s, came, odr)

    def _to_fifo(self, first_s: float, came: int, odr: float) -> None:
        """`came` samples from `first_s` into the FIFO; beyond its 128 packets stop-on-full drops the newest,
        stream mode the oldest; either sets FIFO_FULL."""
        held = len(self._fifo) // regs.PACKET_BYTES + sum(n for _, n in self._fifo_pending)
        room = regs.FIFO_PACKETS - held
        if came >= room:
            self._regs[regs.REG_INT_STATUS] |= regs.INT_STATUS_FIFO_FULL
        if self._regs[regs.REG_FIFO_CONFIG] & 0xC0 == 0x40:  # stream: the newest kept, the oldest dropped
            self._fifo_pending.append((first_s, came))
            self._drop_oldest(held + came - regs.FIFO_PACKETS, odr)
        elif room > 0:
            self._fifo_pending.append((first_s, min(came, room)))

    def _drop_oldest(self, excess: int, odr: float) -> None:
        if excess <= 0:
            return
        made = min(excess, len(self._fifo) // regs.PACKET_BYTES)
        del self._fifo[:made * regs.PACKET_BYTES]
        excess -= made
        while excess > 0:
            first_s, count = self._fifo_pending[0]
            if count <= excess:
                self._fifo_pending.pop(0)
                excess -= count
            else:
                self._fifo_pending[0] = (first_s + excess / odr, count - excess)
                excess = 0

    def _take_fifo(self, count: int) -> bytes:
        """`count` bytes from the FIFO's read port: its packets (made now), then 0xFF where it is empty."""
        if self._fifo_pending and len(self._fifo) < count:
            for first_s, n in self._fifo_pending:
                self._fifo += self._packets(first_s, n, self._odr_hz)
            self._fifo_pending.clear()
        taken = bytes(self._fifo[:count])
        del self._fifo[:count]
        return taken + b"\xff" * (count - len(taken))

    def _flush(self) -> None:
        self._fifo.clear()
        self._fifo_pending.clear()

    def _packets(self, first_s: float, count: int, odr: float) -> bytes:
        """`count` FIFO packets of both sensors from `first_s` on, from the lab's truth now."""
        accel, gyro = self._codes(first_s, count, odr)
        since = self._ticks.since_s
        first_tick = round((first_s - since) * odr) if since is not None else 1  # sample k is tick k + 1
        period_ns = round(1e9 / odr)
        ticks = (first_tick + np.arange(count, dtype=np.int64)) * period_ns * 30 // 32_000
        return regs.encode_packets(accel, gyro, np.full(count, self._temperature_raw()), ticks)

    def _codes(self, first_s: float, count: int, odr: float) -> tuple[np.ndarray, np.ndarray]:
        accel = self._lab.dut_samples(self._index, first_s, count, odr, self._range("accel", regs.REG_ACCEL_CONFIG0))
        gyro = self._lab.dut_gyro_samples(self._index, first_s, count, odr, self._range("gyro", regs.REG_GYRO_CONFIG0))
        return accel, gyro

    def _make_data(self) -> None:
        """The data registers' newest sample, made when first read after it came."""
        if self._data_due and self._newest_s is not None:
            accel, gyro = self._codes(self._newest_s, 1, self._odr_hz)
            self._sample = regs.encode_sample(0, accel[0], gyro[0])
        self._data_due = False

    def _temperature_raw(self) -> int:
        return int(self._lab.dut_reading_raw(self._index))

    @staticmethod
    def _invalid() -> bytes:
        return np.full(7, regs.DATA_INVALID, dtype=">i2").tobytes()
