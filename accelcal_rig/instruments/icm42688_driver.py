"""A TDK ICM-42688-P at register level over any RegisterTransport (a serial bridge, spidev): bring-up, both
sensors' full scale and rate, its FIFO in packets of both sensors (stop-on-full), temperature, and gap-free blocks
from the FIFO — captured by the bridge where it can (instruments/bridge_block.py), else read by the host in bursts
of whole packets, FIFO_FULL checked at every read so a block that lost a sample is taken again, never returned
short. Register facts: `instruments/icm42688.py`; the part's: `parts/icm42688.py`."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import InstrumentError, WaitTimeout
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.adxl355_transport import PostedRequests, RegisterTransport
from accelcal_rig.instruments.bridge_block import BridgeCapturing, Decoded
from accelcal_rig.instruments.capabilities import Reconnecting
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.retrying import RetryCall, RetryingTransport
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.part import Part

#: Soft reset: the data sheet asks 1 ms before the next access; RESET_DONE is awaited with this deadline.
RESET_TIMEOUT_S = 0.1
RESET_POLL_S = 0.001
#: After PWR_MGMT0 turns the gyroscope on, its data are not valid for this long (the Linux driver waits 60 ms).
GYRO_STARTUP_S = 0.06
#: Packets to let gather between the host's reads of the FIFO: half its 128, so a read is never late.
DRAIN_EVERY_PACKETS = 64
#: Packets in one burst of FIFO_DATA: the bridge's longest read (288 bytes) holds 18 whole packets.
BURST_PACKETS = 18


class Icm42688(BridgeCapturing):
    """The Sensor of an ICM-42688-P DUT: channels `accel` (g) and `gyro` (°/s), 16-bit codes."""

    fifo_loss = "FIFO full"

    def __init__(self, transport: RegisterTransport, serial: str, clock: Clock, part: Part = ICM42688P) -> None:
        self.part = part
        self._bare: RegisterTransport = transport
        self._bus: RegisterTransport = transport
        #: The bare transport where it posts requests; FIFO bursts go there too, never retried alone (a lost
        #: reply took packets with it: the block is taken again whole).
        self._poster = transport if isinstance(transport, PostedRequests) else None
        self.serial = serial
        self.endpoint = transport.endpoint
        self._clock = clock
        self._odr_hz = 100.0

    def _fault(self, message: str) -> InstrumentError:
        return InstrumentError(f"sensor {self.serial} ({self.endpoint}): {message}")

    # ------------------------------------------------------------------ the Sensor interface
    def identify(self) -> DeviceIdentity:
        """WHO_AM_I (bank 0: selected first, whatever bank a previous user left)."""
        self._bus.write(regs.REG_BANK_SEL, 0)
        return DeviceIdentity((self._bus.read(regs.REG_WHO_AM_I, 1)[0],))  # no revision register

    def reset(self) -> None:
        """Soft reset (DEVICE_CONFIG), then wait with a deadline for INT_STATUS's RESET_DONE."""
        self._bus.write(regs.REG_BANK_SEL, 0)
        self._bus.write(regs.REG_DEVICE_CONFIG, regs.DEVICE_CONFIG_SOFT_RESET)
        try:
            wait_until(self._clock, lambda: bool(self._bus.read(regs.REG_INT_STATUS, 1)[0] & regs.INT_STATUS_RESET_DONE),
                       timeout_s=RESET_TIMEOUT_S, poll_s=RESET_POLL_S,
                       what=f"sensor {self.serial} ({self.endpoint}) RESET_DONE after soft reset")
        except WaitTimeout as exc:
            raise InstrumentError(str(exc)) from None

    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        """Both sensors' full scale and the one output data rate, and the FIFO (packets of both sensors and the
        temperature, stop-on-full), written and read back; in standby, as the data sheet asks of the FIFO's set-up."""
        missing = [c.name for c in self.part.channels if c.name not in ranges]
        if missing:
            raise self._fault(f"no range given for its {', '.join(missing)} channel")
        odr = self.part.odr_code(odr_hz)
        gyro = regs.config0(self.part.channel("gyro").range_codes[ranges["gyro"]], odr)
        accel = regs.config0(self.part.channel("accel").range_codes[ranges["accel"]], odr)
        self._bus.write(regs.REG_GYRO_CONFIG0, gyro)
        self._bus.write(regs.REG_ACCEL_CONFIG0, accel)
        readback = tuple(self._bus.read(regs.REG_GYRO_CONFIG0, 2))
        if readback != (gyro, accel):
            raise self._fault(f"GYRO_CONFIG0/ACCEL_CONFIG0 read back {readback[0]:02X}/{readback[1]:02X}, "
                              f"not {gyro:02X}/{accel:02X}")
        self._bus.write(regs.REG_FIFO_CONFIG1, regs.FIFO_CONFIG1_ACCEL_GYRO_TEMP)
        self._bus.write(regs.REG_FIFO_CONFIG, regs.FIFO_MODE_STOP_ON_FULL)
        fifo = self._bus.read(regs.REG_FIFO_CONFIG, 1)[0], self._bus.read(regs.REG_FIFO_CONFIG1, 1)[0]
        if fifo != (regs.FIFO_MODE_STOP_ON_FULL, regs.FIFO_CONFIG1_ACCEL_GYRO_TEMP):
            raise self._fault(f"FIFO_CONFIG/FIFO_CONFIG1 read back {fifo[0]:02X}/{fifo[1]:02X}, not "
                              f"{regs.FIFO_MODE_STOP_ON_FULL:02X}/{regs.FIFO_CONFIG1_ACCEL_GYRO_TEMP:02X}")
        self._odr_hz = odr_hz

    def start_measurement(self) -> None:
        """Both sensors in low-noise mode, temperature on; wait out the gyroscope's start-up."""
        self._bus.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_LOW_NOISE)
        self._clock.sleep(GYRO_STARTUP_S)

    def standby(self) -> None:
        self._bus.write(regs.REG_PWR_MGMT0, regs.PWR_MGMT0_OFF)

    def read_settings(self) -> tuple[dict[str, float], float]:
        """(each channel's range, the output data rate) as GYRO_CONFIG0 and ACCEL_CONFIG0 hold them."""
        gyro_value, accel_value = self._bus.read(regs.REG_GYRO_CONFIG0, 2)
        settings: dict[str, float] = {}
        rates = set()
        for name, value in (("gyro", gyro_value), ("accel", accel_value)):
            fs_sel, odr_code = regs.split_config0(value)
            by_code = {code: range_ for range_, code in self.part.channel(name).range_codes.items()}
            rate = self.part.odr_for_code(odr_code)
            if fs_sel not in by_code or rate is None:
                raise self._fault(f"{name.upper()}_CONFIG0 reads 0x{value:02X}: no range or rate of the {self.part.label}")
            settings[name] = by_code[fs_sel]
            rates.add(rate)
        if len(rates) != 1:
            raise self._fault(f"the gyroscope and accelerometer run at different rates ({sorted(rates)} Hz)")
        return settings, rates.pop()

    def read_temperature_c(self) -> float:
        """TEMP_DATA1/TEMP_DATA0 in one burst."""
        raw = int(regs.decode_words(self._bus.read(regs.REG_TEMP_DATA1, 2))[0])
        if raw == regs.DATA_INVALID:
            raise self._fault("TEMP_DATA holds no reading (is the part powered down?)")
        return float(self.part.temperature.celsius(raw))

    def close(self) -> None:
        self._bus.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each register access on its own (a retried sample burst whose first reply was lost reads
        DATA_RDY clear, so that sample is read as late and its block taken again)."""
        self._bus = RetryingTransport(self._bare, call)

    def reconnect(self) -> None:
        if isinstance(self._bare, Reconnecting):
            self._bare.reconnect()

    # ------------------------------------------------------------------ the FIFO
    def _decode_fifo(self, raw: bytes, carried: bytes) -> Decoded:
        """Whole packets (a bridge's capture, a burst of whole packets): both channels' codes; nothing carried."""
        try:
            accel, gyro, _ = regs.decode_packets(carried + raw)
        except ValueError as exc:
            raise self._fault(f"FIFO: {exc}") from None
        if np.any(np.all(accel == regs.DATA_INVALID, axis=1)) or np.any(np.all(gyro == regs.DATA_INVALID, axis=1)):
            raise self._fault("a FIFO packet holds no reading (is the part measuring?)")
        return {"accel": accel, "gyro": gyro}, b""

    def _try_drain(self, n_samples: int) -> SampleBlock | None:
        """One attempt read by the host: the FIFO flushed, then every DRAIN_EVERY_PACKETS samples its count and
        that many whole packets; None where INT_STATUS's FIFO_FULL (cleared by reading it) says a sample may have
        been dropped since the read before."""
        self._bus.write(regs.REG_SIGNAL_PATH_RESET, regs.SIGNAL_PATH_RESET_FIFO_FLUSH)
        self._status_and_count()  # clears a stale FIFO_FULL; the data sheet's first count after a flush is 0
        t_start = self._clock.now()
        temperature_before = self.read_temperature_c()
        pieces: list[dict[str, np.ndarray]] = []
        have = 0
        deadline = t_start + 2.0 * n_samples / self._odr_hz + 1.0
        while have < n_samples:
            if self._clock.now() > deadline:
                raise self._fault(f"{have} of {n_samples} samples before the deadline: is it measuring?")
            self._clock.sleep(min(DRAIN_EVERY_PACKETS, n_samples - have) / self._odr_hz)
            status, count = self._status_and_count()
            if status & regs.INT_STATUS_FIFO_FULL:
                return None
            packets = count // regs.PACKET_BYTES
            while packets:
                burst = min(packets, BURST_PACKETS)
                codes, _ = self._decode_fifo(self._bare.read(regs.REG_FIFO_DATA, burst * regs.PACKET_BYTES), b"")
                pieces.append(codes)
                have += burst
                packets -= burst
        return self._block(pieces, n_samples, t_start, (temperature_before, self.read_temperature_c()))

    def _status_and_count(self) -> tuple[int, int]:
        """INT_STATUS (read-to-clear) and FIFO_COUNT in bytes, in one burst from INT_STATUS: COUNTH read first. On
        the bare transport, never retried alone: a reply lost after the read cleared FIFO_FULL would hide a loss
        from its retry (the block is then taken again whole)."""
        status, high, low = self._bare.read(regs.REG_INT_STATUS, 3)
        return status, high << 8 | low
