"""A simulated ICM-42688-P at register level (user bank 0): WHO_AM_I, soft reset and RESET_DONE, the two
CONFIG0 registers, PWR_MGMT0, and data registers that hold the newest sample of both sensors at the output
data rate on the shared clock, made from the lab's hidden truth of each (DATA_RDY set by a new sample, cleared
by reading INT_STATUS). Register facts: `instruments/icm42688.py`, shared with the driver.

Simplifications (not claims about the chip), the same as the reference firmware's C model of the part
(firmware/host/icm42688_model.h): only bank 0 is modelled (in another bank every register but REG_BANK_SEL reads 0
and ignores writes); a read-only register ignores a write; TEMP_DATA reads the DUT's temperature whatever the power
mode; a sensor off reads DATA_INVALID (-32768) in its data registers; the first sample comes one period after
PWR_MGMT0 turns the sensors on; both sensors sample at ACCEL_CONFIG0's rate, whose code may be one the part's
table does not offer (a low-power rate, or the reserved 0: taken as 1 kHz); a reserved accelerometer FS_SEL (4…7)
is ±16 g.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.sample_ticks import SampleTicks

_DATA = range(regs.REG_TEMP_DATA1, regs.REG_GYRO_DATA_Z0 + 1)
#: Reset values (data sheet register map): both CONFIG0 registers FS_SEL 0, ODR code 6 (1 kHz).
_CONFIG0_RESET = 0x06
#: ODR codes beyond the low-noise rates the part offers: the accelerometer's low-power rates (codes 12…14), and
#: the reserved code 0 taken as 1 kHz (the C model's choice).
_OTHER_ODR_HZ = {0: 1000.0, 12: 6.25, 13: 3.125, 14: 1.5625}
#: The accelerometer's reserved FS_SEL codes (4…7) taken as ±16 g (FS_SEL 0).
_ACCEL_FS_SEL_RESERVED = 4


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
        self._ticks = SampleTicks()
        self._sample = self._invalid()

    def read(self, address: int, count: int) -> bytes:
        """`count` registers from `address` on, within the map (the bridge refuses a burst past it)."""
        span = range(address, address + count)
        if self._bank:
            return bytes(self._regs[regs.REG_BANK_SEL] if reg == regs.REG_BANK_SEL else 0 for reg in span)
        if not set(span).isdisjoint(_DATA) or regs.REG_INT_STATUS in span:
            self._update_data()
        self._regs[regs.REG_TEMP_DATA1:regs.REG_TEMP_DATA1 + 2] = self._temperature()
        self._regs[regs.REG_ACCEL_DATA_X1:regs.REG_GYRO_DATA_Z0 + 1] = self._sample[2:]
        value = bytes(self._regs[address:address + count])
        if regs.REG_INT_STATUS in span:
            self._regs[regs.REG_INT_STATUS] = 0  # clear on read
        return value

    def write(self, address: int, value: int) -> None:
        """What the part does with a write: a read-only register, or any but REG_BANK_SEL in another bank, ignores
        it; DEVICE_CONFIG's SOFT_RESET resets every register."""
        if (self._bank and address != regs.REG_BANK_SEL) or address in regs.READ_ONLY_REGISTERS:
            return
        if address == regs.REG_DEVICE_CONFIG and value & regs.DEVICE_CONFIG_SOFT_RESET:
            self.reset()
            return
        self._update_data()
        was_on = self._measuring
        self._regs[address] = value
        if address == regs.REG_PWR_MGMT0 and was_on != self._measuring:
            if self._measuring:
                self._ticks.start(self._lab.clock.now())
            else:
                self._ticks.stop()
            self._sample = self._invalid()
        elif address in (regs.REG_GYRO_CONFIG0, regs.REG_ACCEL_CONFIG0):
            self._ticks.restart(self._lab.clock.now())

    @property
    def _measuring(self) -> bool:
        mode = self._regs[regs.REG_PWR_MGMT0]
        return (mode & 0x03) == 0x03 and (mode >> 2 & 0x03) == 0x03

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

    def _update_data(self) -> None:
        """The newest sample due by the clock, made when first looked at (a sample nobody reads costs nothing);
        DATA_RDY set when it is new."""
        odr = self._odr_hz if self._ticks.running else 0.0
        newest = self._ticks.newest(self._lab.clock.now(), odr)
        if newest is None:
            return
        t_sample = newest[0]
        accel = self._lab.dut_samples(self._index, t_sample, 1, odr, self._range("accel", regs.REG_ACCEL_CONFIG0))
        gyro = self._lab.dut_gyro_samples(self._index, t_sample, 1, odr, self._range("gyro", regs.REG_GYRO_CONFIG0))
        self._sample = regs.encode_sample(0, accel[0], gyro[0])
        self._regs[regs.REG_INT_STATUS] |= regs.INT_STATUS_DATA_RDY

    def _temperature(self) -> bytes:
        return int(self._lab.dut_reading_raw(self._index)).to_bytes(2, "big", signed=True)

    @staticmethod
    def _invalid() -> bytes:
        return np.full(7, regs.DATA_INVALID, dtype=">i2").tobytes()
