"""The serial bridge's register requests, R and W, in front of a simulated part, checked as the reference firmware
checks them (firmware/src/commands.c, with its part table in sensor.c): the arguments, then the part's register
map (a register it does not have, a read-only one, one written only in standby), then a capture that holds the
FIFO. A request that passes goes to the part, which does with it what the part does."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from accelcal_rig.sim import bridge_refusals as refusals
from accelcal_rig.sim.bridge_numbers import decimal, hex_byte
from accelcal_rig.sim.bridge_refusals import Refusal

#: The longest burst R reads: the ADXL355's whole FIFO, 96 entries of 3 bytes.
MAX_READ = 288
#: Register addresses are 7 bits for every part.
LAST_ADDRESS = 0x7F


class RegisterDevice(Protocol):
    def read(self, address: int, count: int) -> bytes: ...
    def write(self, address: int, value: int) -> None: ...


class CaptureGuard(Protocol):
    """What R and W ask of the bridge's capture (sim/bridge_capture.py)."""

    def holds(self, address: int, count: int) -> bool:
        """Whether a burst of `count` from `address` would take samples a running capture is taking."""

    def before_write(self, address: int) -> None:
        """A write to `address` is about to go to the part (it may end a running capture)."""


@dataclass(frozen=True)
class RegisterMap:
    """A part's register map as the bridge enforces it: the firmware part table's facts."""

    last: int                                   #: the highest address the part has
    read_only: frozenset[int]                   #: bank 0's read-only registers
    burst_stays: int | None = None              #: a register a burst reads again and again (the ADXL355's FIFO_DATA)
    bank_select: int | None = None              #: the register that selects a bank (bits 2:0)
    standby_only: frozenset[int] = frozenset()  #: registers written only while the part is in standby


class RegisterRequests:
    """R and W for one simulated part. `in_standby` says whether the part is in standby (for `standby_only`; the
    firmware reads the power register, a simulator asks its part's state so no read draws noise)."""

    def __init__(self, device: RegisterDevice, registers: RegisterMap, in_standby: Callable[[], bool] = lambda: True,
                 capture: CaptureGuard | None = None) -> None:
        self._device = device
        self._map = registers
        self._in_standby = in_standby
        self._capture = capture
        self._bank = 0

    def read(self, address_text: str, count_text: str) -> str:
        address = _address(address_text)
        count = decimal(count_text, MAX_READ)
        if not count:
            raise Refusal(refusals.bad_count(MAX_READ))
        last = address if address == self._map.burst_stays else address + count - 1
        if last > self._map.last:
            raise Refusal(refusals.no_register(max(address, self._map.last + 1)))
        if self._capture is not None and self._capture.holds(address, count):
            raise Refusal(refusals.FIFO_CAPTURED)
        return "=" + self._device.read(address, count).hex().upper()

    def write(self, address_text: str, value_text: str) -> str:
        address = _address(address_text)
        value = hex_byte(value_text)
        if value is None:
            raise Refusal(refusals.BAD_VALUE)
        if address > self._map.last:
            raise Refusal(refusals.no_register(address))
        if self._bank == 0 and address in self._map.read_only:
            raise Refusal(refusals.read_only(address))  # in another bank nothing is known read-only
        if address in self._map.standby_only and not self._in_standby():
            raise Refusal(refusals.standby_only(address))
        if self._capture is not None:
            self._capture.before_write(address)
        self._device.write(address, value)
        if address == self._map.bank_select:
            self._bank = value & 0x07
        return "="

    def select_bank_0(self) -> None:
        """What every greeting does first on a part with banks, so a client that left it in another bank does not
        hide it (the firmware writes 0 to the bank select before it looks for the part again)."""
        if self._map.bank_select is not None:
            self._device.write(self._map.bank_select, 0)
            self._bank = 0


def _address(text: str) -> int:
    address = hex_byte(text)
    if address is None or address > LAST_ADDRESS:
        raise Refusal(refusals.BAD_ADDRESS)
    return address
