"""A TDK ICM-42688-P at register level over any RegisterTransport (a serial bridge, spidev): bring-up, both
sensors' full scale and rate, temperature, and blocks of samples read from the data registers at the output
data rate on the injected clock (instruments/polled_block.py) — one burst per sample, TEMP_DATA1 up to
INT_STATUS, whose DATA_RDY says the sample is new. Register facts: `instruments/icm42688.py`; the part's: `parts/icm42688.py`."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import InstrumentError, WaitTimeout
from accelcal_rig.instruments import icm42688 as regs
from accelcal_rig.instruments.adxl355_transport import RegisterTransport
from accelcal_rig.instruments.capabilities import Reconnecting
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.polled_block import poll_block
from accelcal_rig.instruments.retrying import RetryCall, RetryingTransport
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.part import Part

#: Soft reset: the data sheet asks 1 ms before the next access; RESET_DONE is awaited with this deadline.
RESET_TIMEOUT_S = 0.1
RESET_POLL_S = 0.001
#: After PWR_MGMT0 turns the gyroscope on, its data are not valid for this long (the Linux driver waits 60 ms).
GYRO_STARTUP_S = 0.06


class Icm42688:
    """The Sensor of an ICM-42688-P DUT: channels `accel` (g) and `gyro` (°/s), 16-bit codes."""

    capture_capacity_samples = 0  # no bridge-side capture: the host polls the data registers

    def __init__(self, transport: RegisterTransport, serial: str, clock: Clock, part: Part = ICM42688P) -> None:
        self.part = part
        self._bare: RegisterTransport = transport
        self._bus: RegisterTransport = transport
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
        """Both sensors' full scale and the one output data rate, written and read back."""
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

    def acquire(self, n_samples: int) -> SampleBlock:
        """`n_samples` consecutive samples, each read once DATA_RDY says it is new (instruments/polled_block.py)."""
        raw, t_start = poll_block(self._clock, self._odr_hz, n_samples, self._read_sample, self._fault)
        temperature, accel, gyro = regs.decode_samples(raw)
        if np.any(accel == regs.DATA_INVALID) or np.any(gyro == regs.DATA_INVALID):
            raise self._fault("a data register holds no reading (is the part measuring?)")
        celsius = self.part.temperature.celsius
        return SampleBlock({"accel": accel, "gyro": gyro}, t_start, t_start + (n_samples - 1) / self._odr_hz,
                           (float(celsius(int(temperature[0]))), float(celsius(int(temperature[-1])))))

    def close(self) -> None:
        self._bus.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each register access on its own (a retried sample burst whose first reply was lost reads
        DATA_RDY clear, so that sample is read as late and its block taken again)."""
        self._bus = RetryingTransport(self._bare, call)

    def reconnect(self) -> None:
        if isinstance(self._bare, Reconnecting):
            self._bare.reconnect()

    # ------------------------------------------------------------------ polling the data registers
    def _read_sample(self) -> tuple[bytes, bool]:
        """One burst TEMP_DATA1…INT_STATUS: (the sample's 14 bytes, INT_STATUS's DATA_RDY, which the read clears)."""
        raw = self._bus.read(regs.REG_TEMP_DATA1, regs.SAMPLE_AND_STATUS_BYTES)
        return raw[:regs.SAMPLE_BYTES], bool(raw[-1] & regs.INT_STATUS_DATA_RDY)
