"""The serial bridge's own capture, C and G (docs/instruments.md, "The serial bridge protocol"), of a simulated
part with a FIFO (an ADXL355's, an ICM-42688-P's), with the reference firmware's refusals and rules
(firmware/src/commands.c): a C forgets the capture before it, even one it refuses; G before any capture is
refused; while a capture runs the FIFO is its own, and a write to a register that changes what the FIFO holds
ends it, which G then reports with how far it got."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from accelcal_rig.sim.bridge_numbers import decimal
from accelcal_rig.sim.bridge_refusals import NEEDS_MEASURING, NO_CAPTURE, Refusal, bad_count, bad_first, capture_stopped


@dataclass(frozen=True)
class CaptureRules:
    """A part's facts the bridge's capture goes by (the firmware's part table): its FIFO's read port, the
    registers whose write ends a running capture, and the refusal of a C the part is not ready for (None: ready)."""

    fifo_data: int
    stream_registers: frozenset[int]
    not_ready: Callable[[], str | None]


class CaptureBuffer:
    """A simulated bridge's capture buffer for one part: how many samples it still wants, the samples as the part's
    FIFO gives them (`sample_bytes` each), and the part's temperature code as the last one came. It stays until
    the next capture starts, so a reply lost on the line can be fetched again."""

    def __init__(self, sample_bytes: int) -> None:
        self._sample_bytes = sample_bytes
        self.left = 0
        self._data = bytearray()
        self._end_temperature: int | None = None

    def start(self, n_samples: int) -> None:
        self.left, self._data, self._end_temperature = n_samples, bytearray(), None

    def stop(self) -> None:
        """Ended early (a write changed the stream): it wants no more samples."""
        self.left = 0

    @property
    def samples(self) -> int:
        return len(self._data) // self._sample_bytes

    def take(self, raw: bytes, count: int, temperature: Callable[[], int]) -> None:
        """`count` samples' bytes in; the temperature read as the last one wanted comes."""
        self.left -= count
        self._data += raw
        if self.left == 0:
            self._end_temperature = temperature()

    def fetch(self, first: int) -> tuple[bytes, int | None]:
        """(the samples from index `first` on, the end temperature once complete)."""
        return bytes(self._data[self._sample_bytes * first:]), self._end_temperature if self.left == 0 else None


class CapturingPart(Protocol):
    """A simulated part whose FIFO the bridge drains into its own buffer (SimulatedAdxl355, SimulatedIcm42688)."""

    @property
    def measuring(self) -> bool: ...
    @property
    def capturing(self) -> bool: ...
    @property
    def captured_samples(self) -> int: ...
    def start_capture(self, n_samples: int) -> int: ...
    def fetch_capture(self, first: int) -> tuple[bytes, int | None]: ...
    def stop_capture(self) -> None: ...


class CaptureRequests:
    """C and G for one simulated part, with a buffer of `capacity` samples."""

    def __init__(self, device: CapturingPart, capacity: int, rules: CaptureRules) -> None:
        self._device = device
        self._capacity = capacity
        self._rules = rules
        self._wanted = 0  # the count of the capture there is (0: none)
        self._stopped_after: int | None = None  # samples in when a write ended it
        self._stopped_by = 0  # the register whose write did

    def start(self, count_text: str) -> str:
        self._wanted, self._stopped_after = 0, None
        count = decimal(count_text, self._capacity)
        if not count:
            raise Refusal(bad_count(self._capacity))
        if not self._device.measuring:
            raise Refusal(NEEDS_MEASURING)
        problem = self._rules.not_ready()
        if problem is not None:
            raise Refusal(problem)
        temperature = self._device.start_capture(count)
        self._wanted = count
        return f"={temperature & 0xFFFF:04X}"  # the two temperature registers as read

    def fetch(self, first_text: str) -> str:
        first = decimal(first_text, self._capacity)
        if first is None:
            raise Refusal(bad_first(self._capacity))
        if not self._wanted:
            raise Refusal(NO_CAPTURE)
        if self._stopped_after is not None:
            raise Refusal(capture_stopped(self._stopped_by, self._stopped_after, self._wanted))
        samples, end_temperature = self._device.fetch_capture(first)
        return "=" + samples.hex().upper() + ("" if end_temperature is None else f"T{end_temperature & 0xFFFF:04X}")

    def holds(self, address: int, count: int) -> bool:
        return self._running() and address <= self._rules.fifo_data < address + count

    def before_write(self, address: int) -> None:
        if address in self._rules.stream_registers and self._running():
            self._stopped_after, self._stopped_by = self._device.captured_samples, address
            self._device.stop_capture()

    def _running(self) -> bool:
        return bool(self._wanted) and self._stopped_after is None and self._device.capturing
