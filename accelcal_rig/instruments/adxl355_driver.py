"""An ADXL355 (or a register-compatible ADXL357/ADXL359, by its part table) at register level over any
RegisterTransport: bring-up, configuration, temperature, and gap-free blocks of samples (decoded with
numpy, not per sample) — captured by the bridge where it can, else drained from the FIFO by the host."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import InstrumentError, WaitTimeout
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_transport import PostedRequests, RegisterTransport
from accelcal_rig.instruments.bridge_block import BridgeCapturing, Decoded
from accelcal_rig.instruments.capabilities import Reconnecting
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.retrying import RetryCall, RetryingTransport
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.parts.part import Part

#: Samples to let accumulate between FIFO bursts: under its 32, so a burst is never late.
DRAIN_EVERY_SAMPLES = 30
#: Two temperature reads this close agree; a torn read is a whole TEMP2 step (256 LSB) off.
TEMPERATURE_AGREE_LSB = 16
#: Reads of a temperature before giving up: a part that tears this often is faulty.
TEMPERATURE_READS = 10
#: A single read within TEMPERATURE_AGREE_LSB of a temperature agreed this recently is not torn: a torn one
#: is 240+ LSB (26 °C) from the truth, which no DUT in a chamber moves in a minute (ramps are ≤ 10 °C/min).
AGREED_FRESH_S = 60.0


class Adxl355(BridgeCapturing):
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
        #: (clock time, raw code) of the last temperature that two reads agreed on.
        self._agreed: tuple[float, int] | None = None

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

    def close(self) -> None:
        self._bus.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each register access and capture request on its own (the capture is fetched by index, so
        that is safe); a FIFO burst is not, its block is taken again whole by the caller."""
        self._bus = RetryingTransport(self._fifo_bus, call)

    def reconnect(self) -> None:
        if isinstance(self._fifo_bus, Reconnecting):
            self._fifo_bus.reconnect()

    # ------------------------------------------------------------------ bridge-side capture (instruments/bridge_block.py)
    def _decode_fifo(self, raw: bytes, carried: bytes) -> Decoded:
        codes, carried = adxl355.decode_fifo(raw, carried)
        return {"accel": codes}, carried

    # ------------------------------------------------------------------ host-drained FIFO

    def _try_drain(self, n_samples: int) -> SampleBlock | None:
        """One attempt: a whole-FIFO burst every DRAIN_EVERY_SAMPLES samples (empty entries are marked, a
        sample still being written is carried to the next burst); FIFO_OVR, latched until STATUS is
        read, is checked at the end, so a block that lost samples anywhere is never returned."""
        self._status_and_temperature()  # clears a stale FIFO_OVR
        self._burst(b"")  # stale samples from before this block
        t_start = self._clock.now()
        _, temperature_before = self._status_and_temperature()
        pieces: list[dict[str, np.ndarray]] = []
        have, carried = 0, b""
        deadline = t_start + 2.0 * n_samples / self._odr_hz + 1.0
        while have < n_samples:
            if self._clock.now() > deadline:
                raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {have} of {n_samples} samples "
                                      "before the deadline: is it measuring?")
            self._clock.sleep(min(DRAIN_EVERY_SAMPLES, n_samples - have) / self._odr_hz)
            codes, carried = self._burst(carried)
            pieces.append({"accel": codes})
            have += len(codes)
        status, temperature_after = self._status_and_temperature(bare=True)
        if status & adxl355.STATUS_FIFO_OVR:
            return None
        return self._block(pieces, n_samples, t_start, (temperature_before, temperature_after))

    def _burst(self, carried: bytes) -> tuple[np.ndarray, bytes]:
        """Read the whole FIFO in one burst."""
        raw = self._fifo_bus.read(adxl355.REG_FIFO_DATA, 3 * adxl355.FIFO_CAPACITY_ENTRIES)
        return adxl355.decode_fifo(raw, carried)

    def _status_and_temperature(self, bare: bool = False) -> tuple[int, float]:
        """STATUS, FIFO_ENTRIES, TEMP2 and TEMP1 are neighbours: one burst, then the temperature read again
        until two reads agree (the burst's may have torn). `bare`: the burst on the bare transport, never retried
        alone — STATUS's FIFO_OVR clears as it is read, so a reply lost after that read would hide the loss from
        its retry (a lost reply fails the block, which is taken again whole)."""
        status, _, high, low = (self._fifo_bus if bare else self._bus).read(adxl355.REG_STATUS, 4)
        return self._agreed_temperature_c((status, adxl355.raw_temperature(high, low)))

    def _status(self) -> int:
        return self._bus.read(adxl355.REG_STATUS, 1)[0]

