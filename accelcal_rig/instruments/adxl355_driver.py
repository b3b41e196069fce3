"""An ADXL355 (or a register-compatible ADXL357/ADXL359, by its part table) at register level over any
RegisterTransport: bring-up, configuration, temperature, and gap-free blocks of samples (decoded with
numpy, not per sample) — captured by the bridge where it can, else drained from the FIFO by the host."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import InstrumentError, TransientInstrumentError, WaitTimeout
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_transport import BlockCapture, PostedRequests, RegisterTransport
from accelcal_rig.instruments.capabilities import Reconnecting
from accelcal_rig.instruments.capture import OVERFLOW_ATTEMPTS, capture_together
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.retrying import RetryCall, RetryingTransport
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.parts.part import Part

T = TypeVar("T")

#: Samples to let accumulate between FIFO bursts: under its 32, so a burst is never late.
DRAIN_EVERY_SAMPLES = 30
#: Two temperature reads this close agree; a torn read is a whole TEMP2 step (256 LSB) off.
TEMPERATURE_AGREE_LSB = 16
#: Reads of a temperature before giving up: a part that tears this often is faulty.
TEMPERATURE_READS = 10
#: A single read within TEMPERATURE_AGREE_LSB of a temperature agreed this recently is not torn: a torn one
#: is 240+ LSB (26 °C) from the truth, which no DUT in a chamber moves in a minute (ramps are ≤ 10 °C/min).
AGREED_FRESH_S = 60.0


@dataclass
class _Capture:
    """A block being captured by the bridge: what is known so far."""

    n_samples: int
    t_start_s: float
    temperature_before_c: float
    blocks: list[np.ndarray] = field(default_factory=list)
    have: int = 0
    carried: bytes = b""
    temperature_after_c: float | None = None


class Adxl355:
    def __init__(self, transport: RegisterTransport, serial: str, clock: Clock,
                 part: Part = ADXL355) -> None:
        self.part = part
        self._bus: RegisterTransport = transport
        self._fifo_bus = transport  # FIFO bursts are never retried alone: a lost reply took samples with it
        #: The bare transport where it posts requests (asked once: it is asked for every DUT at every poll).
        self._poster = transport if isinstance(transport, PostedRequests) else None
        self.serial = serial
        self.endpoint = transport.endpoint
        self._clock = clock
        self._odr_hz = 125.0
        self._capture: _Capture | None = None
        #: Clock time the last capture request was posted: when the bridge started it, however much later
        #: its reply is read (after another DUT's retries, say).
        self._capture_posted_s: float | None = None
        #: (clock time, raw code) of the last temperature that two reads agreed on.
        self._agreed: tuple[float, int] | None = None

    @property
    def capture_capacity_samples(self) -> int:
        """The largest block the bridge captures itself (0: none; the host drains the FIFO)."""
        return self._bus.capture_capacity_samples

    # ------------------------------------------------------------------ the Sensor interface
    def identify(self) -> DeviceIdentity:
        ad, mst, part, rev = self._bus.read(adxl355.REG_DEVID_AD, 4)
        return DeviceIdentity((ad, mst, part), rev)

    def reset(self) -> None:
        """Software reset, then wait (with a deadline) for the NVM to load."""
        self._bus.write(adxl355.REG_RESET, adxl355.RESET_CODE)
        try:
            wait_until(self._clock, lambda: not self._status() & adxl355.STATUS_NVM_BUSY,
                       timeout_s=0.1, poll_s=0.005, what=f"sensor {self.serial} ({self.endpoint}) NVM load after reset")
        except WaitTimeout as exc:
            raise InstrumentError(str(exc)) from None

    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        """Range and filter, written explicitly; the part takes them only in standby."""
        range_g, range_codes = ranges["accel"], self.part.channel("accel").range_codes
        if not self._bus.read(adxl355.REG_POWER_CTL, 1)[0] & adxl355.POWER_CTL_STANDBY:
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): range and filter can only change in standby")
        self._bus.write(adxl355.REG_RANGE, range_codes[range_g])
        self._bus.write(adxl355.REG_FILTER, self.part.odr_code(odr_hz))
        readback = self._bus.read(adxl355.REG_FILTER, 1)[0], self._bus.read(adxl355.REG_RANGE, 1)[0] & 0x03
        if readback != (self.part.odr_code(odr_hz), range_codes[range_g]):
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): range/filter did not read back")
        self._odr_hz = odr_hz

    def start_measurement(self) -> None:
        self._bus.write(adxl355.REG_POWER_CTL, 0x00)  # measure, temperature on, DRDY on

    def standby(self) -> None:
        self._bus.write(adxl355.REG_POWER_CTL, adxl355.POWER_CTL_STANDBY)

    def read_settings(self) -> tuple[dict[str, float], float]:
        """(the acceleration's range in g, output data rate in Hz) as the part is configured now."""
        filter_code = self._bus.read(adxl355.REG_FILTER, 1)[0] & 0x0F
        range_code = self._bus.read(adxl355.REG_RANGE, 1)[0] & 0x03
        ranges = {code: g for g, code in self.part.channel("accel").range_codes.items()}
        if range_code not in ranges or filter_code >= len(self.part.output_data_rates_hz):
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): RANGE/FILTER read back invalid codes")
        return {"accel": ranges[range_code]}, self.part.output_data_rates_hz[filter_code]

    def read_temperature_c(self) -> float:
        """One read where it agrees with a fresh agreed temperature (a soak poll's usual case), else read
        until two agree."""
        if self._agreed is not None and self._clock.now() - self._agreed[0] <= AGREED_FRESH_S:
            high, low = self._bus.read(adxl355.REG_TEMP2, 2)
            raw = adxl355.raw_temperature(high, low)
            if abs(raw - self._agreed[1]) <= TEMPERATURE_AGREE_LSB:
                self._agreed = (self._clock.now(), raw)
                return float(self.part.temperature.celsius(raw))
            return self._agreed_temperature_c((0, raw))[1]
        return self._agreed_temperature_c(None)[1]

    def begin_temperature_read(self) -> bool:
        """Send the one read of `read_temperature_c`'s usual case without waiting for its reply (False: not
        sent, read it with `read_temperature_c`)."""
        if self._agreed is None or self._clock.now() - self._agreed[0] > AGREED_FRESH_S:
            return False
        return self._posted(lambda bridge: bridge.post_read(adxl355.REG_TEMP2, 2))

    def end_temperature_read(self) -> float | None:
        """The temperature `begin_temperature_read` asked for; None where it does not agree with the last
        agreed one or the exchange failed (read it again with `read_temperature_c`, which retries)."""
        assert self._agreed is not None
        read = self._received(True, lambda bridge: bridge.receive_read(adxl355.REG_TEMP2, 2))
        if read is None:
            return None
        raw = adxl355.raw_temperature(*read)
        if abs(raw - self._agreed[1]) > TEMPERATURE_AGREE_LSB:
            return None
        self._agreed = (self._clock.now(), raw)
        return float(self.part.temperature.celsius(raw))

    def _agreed_temperature_c(self, first: tuple[int, int] | None) -> tuple[int, float]:
        """TEMP2 and TEMP1 are not double-buffered (data sheet): a read can straddle an update of the high
        nibble and be off by 256 LSB, ~28 °C. Read until two reads in a row agree; the later one counts.
        `first`: (STATUS, raw temperature) of a burst that read them already; returns (its STATUS, °C)."""
        status, previous = first if first is not None else (0, None)
        for _ in range(TEMPERATURE_READS):
            high, low = self._bus.read(adxl355.REG_TEMP2, 2)
            raw = adxl355.raw_temperature(high, low)
            if previous is not None and abs(raw - previous) <= TEMPERATURE_AGREE_LSB:
                self._agreed = (self._clock.now(), raw)
                return status, float(self.part.temperature.celsius(raw))
            previous = raw
        raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {TEMPERATURE_READS} temperature reads in a "
                              "row, no two consecutive ones agreeing (TEMP2/TEMP1 tearing)")

    def acquire(self, n_samples: int) -> SampleBlock:
        """`n_samples` consecutive samples, captured by the bridge if it can, else drained from the FIFO."""
        if 0 < n_samples <= self.capture_capacity_samples:
            return capture_together([self], n_samples, self._clock)[0]
        for _ in range(OVERFLOW_ATTEMPTS):
            block = self._try_drain(n_samples)
            if block is not None:
                return block
        raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): FIFO overflowed in {OVERFLOW_ATTEMPTS} "
                              f"attempts: the link cannot keep up with {self._odr_hz:g} Hz")

    def close(self) -> None:
        self._bus.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each register access and capture request on its own (the capture is fetched by index, so
        that is safe); a FIFO burst is not, its block is taken again whole by the caller."""
        self._bus = RetryingTransport(self._fifo_bus, call)

    def reconnect(self) -> None:
        if isinstance(self._fifo_bus, Reconnecting):
            self._fifo_bus.reconnect()

    # ------------------------------------------------------------------ bridge-side capture
    def post_capture(self, n_samples: int) -> bool:
        """Send the capture request without waiting for its reply (False: not sent; `begin_capture` asks)."""
        self._capture_posted_s = self._clock.now()
        return self._posted(lambda bridge: bridge.post_capture(n_samples))

    def begin_capture(self, n_samples: int, posted: bool = False) -> None:
        """The bridge starts capturing the next `n_samples` (and says the temperature then). `posted`: the
        request went out with `post_capture`; its reply is read here, or the request retried if it failed.
        The block starts when the bridge heard the request that started it, not when its reply was read:
        the replies of posted requests are read one DUT after another, after any retries of those before."""
        raw = self._received(posted, lambda bridge: bridge.receive_capture(n_samples))
        if raw is not None and self._capture_posted_s is not None:
            started_s = self._capture_posted_s
        else:  # not posted, or its reply lost: a capture started again now, by the retried request
            raw = self._capturing_bus().start_capture(n_samples)
            started_s = self._clock.now()
        self._capture_posted_s = None
        self._capture = _Capture(n_samples, started_s, float(self.part.temperature.celsius(raw)))

    def capture_wait_s(self) -> float:
        """Clock time until the rest of the block has been captured."""
        assert self._capture is not None
        return (self._capture.n_samples - self._capture.have) / self._odr_hz

    def post_fetch(self) -> bool:
        """Send the next fetch without waiting for its reply (False: not sent; `fetch_capture` asks)."""
        assert self._capture is not None
        have = self._capture.have
        return self._posted(lambda bridge: bridge.post_fetch(have))

    def fetch_capture(self, posted: bool = False) -> bool:
        """Fetch what the bridge has captured since the last fetch (asked for by index, so a retry after
        a lost reply loses nothing); True once the block is complete. A capture that lost samples raises
        CaptureOverflow; one that stalls past its deadline is a fault. `posted`: as for `begin_capture`."""
        capture = self._capture
        assert capture is not None
        fetched = self._received(posted, lambda bridge: bridge.receive_fetch(capture.have))
        raw, temperature_raw = fetched if fetched is not None else self._capturing_bus().fetch_capture(capture.have)
        codes, capture.carried = adxl355.decode_fifo(raw, capture.carried)
        capture.blocks.append(codes)
        capture.have += len(codes)
        if temperature_raw is not None:
            capture.temperature_after_c = float(self.part.temperature.celsius(temperature_raw))
        done = capture.have >= capture.n_samples
        if not done and self._clock.now() > capture.t_start_s + 2.0 * capture.n_samples / self._odr_hz + 1.0:
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {capture.have} of {capture.n_samples} "
                                  "samples before the deadline: is it measuring?")
        return done

    def _capturing_bus(self) -> BlockCapture:
        """The (retried) transport, as one that captures blocks: only such a one has a capture capacity."""
        bus = self._bus
        if not isinstance(bus, BlockCapture):
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): its transport captures no blocks")
        return bus

    def _posted(self, send: Callable[[PostedRequests], None]) -> bool:
        """Send a request with `send` on the bare transport, if it posts requests (no retry: a failure is
        retried whole by the exchange that follows)."""
        if self._poster is None:
            return False
        try:
            send(self._poster)
        except TransientInstrumentError:
            return False
        return True

    def _received(self, posted: bool, receive: Callable[[PostedRequests], T]) -> T | None:
        """The reply to a posted request; None when none was posted or it failed transiently (ask again)."""
        if not posted or self._poster is None:
            return None
        try:
            return receive(self._poster)
        except TransientInstrumentError:
            return None

    def end_capture(self) -> SampleBlock:
        """The completed block, with the temperature the bridge read as it completed."""
        capture = self._capture
        assert capture is not None and capture.have >= capture.n_samples
        self._capture = None
        if capture.temperature_after_c is None:
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): the bridge completed a capture "
                                  "without its end temperature")
        return self._block(capture.blocks, capture.n_samples, capture.t_start_s,
                           (capture.temperature_before_c, capture.temperature_after_c))

    # ------------------------------------------------------------------ host-drained FIFO

    def _try_drain(self, n_samples: int) -> SampleBlock | None:
        """One attempt: a whole-FIFO burst every DRAIN_EVERY_SAMPLES samples (empty entries are marked, a
        sample still being written is carried to the next burst); FIFO_OVR, latched until STATUS is
        read, is checked at the end, so a block that lost samples anywhere is never returned."""
        self._status_and_temperature()  # clears a stale FIFO_OVR
        self._burst(b"")  # stale samples from before this block
        t_start = self._clock.now()
        _, temperature_before = self._status_and_temperature()
        blocks, have, carried = [], 0, b""
        deadline = t_start + 2.0 * n_samples / self._odr_hz + 1.0
        while have < n_samples:
            if self._clock.now() > deadline:
                raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {have} of {n_samples} samples "
                                      "before the deadline: is it measuring?")
            self._clock.sleep(min(DRAIN_EVERY_SAMPLES, n_samples - have) / self._odr_hz)
            codes, carried = self._burst(carried)
            blocks.append(codes)
            have += len(codes)
        status, temperature_after = self._status_and_temperature()
        if status & adxl355.STATUS_FIFO_OVR:
            return None
        return self._block(blocks, n_samples, t_start, (temperature_before, temperature_after))

    def _block(self, blocks: list[np.ndarray], n_samples: int, t_start: float,
               temperature_c: tuple[float, float]) -> SampleBlock:
        codes = np.concatenate(blocks)[:n_samples]
        return SampleBlock({"accel": codes}, t_start, t_start + (n_samples - 1) / self._odr_hz, temperature_c)

    def _burst(self, carried: bytes) -> tuple[np.ndarray, bytes]:
        """Read the whole FIFO in one burst."""
        raw = self._fifo_bus.read(adxl355.REG_FIFO_DATA, 3 * adxl355.FIFO_CAPACITY_ENTRIES)
        return adxl355.decode_fifo(raw, carried)

    def _status_and_temperature(self) -> tuple[int, float]:
        """STATUS, FIFO_ENTRIES, TEMP2 and TEMP1 are neighbours: one burst, then the temperature read again
        until two reads agree (the burst's may have torn)."""
        status, _, high, low = self._bus.read(adxl355.REG_STATUS, 4)
        return self._agreed_temperature_c((status, adxl355.raw_temperature(high, low)))

    def _status(self) -> int:
        return self._bus.read(adxl355.REG_STATUS, 1)[0]

