"""A simulated LIS3MDL at register level: WHO_AM_I, soft reset (SOFT_RST clears itself), the CTRL registers and
their reset values, STATUS, and data registers that hold the newest sample at the output data rate on the
shared clock, made from the lab's hidden truth of the DUT's magnetometer in the site's field at the table's true
angles (ZYXDA set by a new sample, cleared by reading the data; ZYXOR when a sample went by unread). Register
facts: `instruments/lis3mdl.py`, shared with the driver.

Simplifications (not claims about the chip): a read-only or reserved register ignores a write; TEMP_OUT reads
the DUT's temperature whatever TEMP_EN says; the first sample comes one period after continuous conversion
starts; single-conversion mode (MD 01) converts like continuous mode; the OFFSET registers, self-test, BDU,
FAST_READ and the interrupt generator hold what is written and do nothing.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.instruments import lis3mdl as regs
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.sample_ticks import SampleTicks

_DATA = range(regs.REG_OUT_X_L, regs.REG_OUT_X_L + 6)


class SimulatedLis3mdl:
    """One DUT's LIS3MDL, fed by the lab's truth of its magnetometer."""

    def __init__(self, lab: VirtualLab, index: int, wrong_who_am_i: bool = False) -> None:
        self._lab = lab
        self._index = index
        self._part = lab.duts[index].part
        self._channel = self._part.channels[0]
        self._who_am_i = (self._part.identity[0] ^ 0x07) if wrong_who_am_i else self._part.identity[0]
        self.reset()

    def reset(self) -> None:
        self._regs = bytearray(regs.REG_LAST + 1)
        for address, value in regs.RESET_VALUES.items():
            self._regs[address] = value
        self._regs[regs.REG_WHO_AM_I] = self._who_am_i
        self._ticks = SampleTicks()
        self._sample = np.zeros(3, dtype=np.int32)

    def read(self, address: int, count: int) -> bytes:
        """`count` registers from `address` on, within the map (the bridge refuses a burst past it)."""
        span = range(address, address + count)
        if regs.REG_STATUS in span or not set(span).isdisjoint(_DATA):
            self._update_data()
        big_endian = bool(self._regs[regs.REG_CTRL4] & regs.CTRL4_BLE)
        self._regs[regs.REG_OUT_X_L:regs.REG_OUT_X_L + 6] = regs.encode_words(self._sample, big_endian)
        self._regs[regs.REG_TEMP_OUT_L:regs.REG_TEMP_OUT_L + 2] = regs.encode_words(
            np.array([self._lab.dut_reading_raw(self._index)]), big_endian)
        value = bytes(self._regs[address:address + count])
        if not set(span).isdisjoint(_DATA):
            self._regs[regs.REG_STATUS] = 0  # the sample read: not new, and none went by unread
        return value

    def write(self, address: int, value: int) -> None:
        """What the part does with a write: a read-only or reserved register ignores it; CTRL_REG2's SOFT_RST
        resets every register (and clears itself)."""
        if address in regs.READ_ONLY_REGISTERS or address in regs.RESERVED:
            return
        if address == regs.REG_CTRL2 and value & regs.CTRL2_SOFT_RST:
            self.reset()
            return
        self._update_data()
        was_on = self._measuring
        self._regs[address] = value
        if address == regs.REG_CTRL3 and was_on != self._measuring:
            if self._measuring:
                self._ticks.start(self._lab.clock.now())
            else:
                self._ticks.stop()
        elif address == regs.REG_CTRL1:
            self._ticks.restart(self._lab.clock.now())

    @property
    def _measuring(self) -> bool:
        return (self._regs[regs.REG_CTRL3] & 0x03) in (0x00, 0x01)

    @property
    def _odr_hz(self) -> float:
        rate = self._part.odr_for_code(regs.rate_code_of(self._regs[regs.REG_CTRL1]))
        if rate is not None:
            return rate
        # A code the table does not list: its DO bits' rate in the x and y axes' mode (FAST_ODR with another
        # DO is the same fast rate).
        return self._part.output_data_rates_hz[(self._regs[regs.REG_CTRL1] >> 2) & 0x07]

    def _range(self) -> float:
        by_code = {code: r for r, code in self._channel.range_codes.items()}
        return by_code[regs.fs_of(self._regs[regs.REG_CTRL2])]

    def _update_data(self) -> None:
        """The newest sample due by the clock, made when first looked at; ZYXDA set when it is new, ZYXOR when
        one before it went by unread."""
        odr = self._odr_hz if self._ticks.running else 0.0
        newest = self._ticks.newest(self._lab.clock.now(), odr)
        if newest is None:
            return
        t_sample, came = newest
        unread = bool(self._regs[regs.REG_STATUS] & regs.STATUS_ZYXDA) or came > 1
        self._sample = self._lab.dut_field_samples(self._index, t_sample, 1, odr, self._range())[0]
        self._regs[regs.REG_STATUS] = regs.STATUS_ZYXDA | 0x07 | ((regs.STATUS_ZYXOR | 0x70) if unread else 0)
