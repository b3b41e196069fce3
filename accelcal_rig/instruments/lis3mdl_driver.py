"""An ST LIS3MDL at register level over any RegisterTransport (a serial bridge, spidev): bring-up, full scale and
rate (the z axis in the x and y axes' operating mode), the temperature sensor, and blocks of samples read from
the data registers at the output data rate on the injected clock (instruments/polled_block.py) — one burst per
sample, STATUS up to TEMP_OUT_H, whose ZYXDA says the sample is new. Register facts: `instruments/lis3mdl.py`;
the part's: `parts/lis3mdl.py`."""

from __future__ import annotations

from collections.abc import Mapping

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import InstrumentError, WaitTimeout
from accelcal_rig.instruments import lis3mdl as regs
from accelcal_rig.instruments.adxl355_transport import RegisterTransport
from accelcal_rig.instruments.capabilities import Reconnecting
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.polled_block import poll_block
from accelcal_rig.instruments.retrying import RetryCall, RetryingTransport
from accelcal_rig.parts.lis3mdl import LIS3MDL
from accelcal_rig.parts.part import Part

#: SOFT_RST clears itself when the reset is done (ST's driver polls it); the data sheet gives no duration: awaited
#: with this deadline.
RESET_TIMEOUT_S = 0.1
RESET_POLL_S = 0.001
#: After the part leaves power-down its first conversion takes up to a period; ultra-high performance's turn-on
#: time (AN4602) is 6.65 ms: waited before the first block.
TURN_ON_S = 0.01


class Lis3mdl:
    """The Sensor of an LIS3MDL DUT: its one channel, the part's (`mag`, gauss), 16-bit codes."""

    capture_capacity_samples = 0  # no bridge-side capture: the host polls the data registers

    def __init__(self, transport: RegisterTransport, serial: str, clock: Clock, part: Part = LIS3MDL) -> None:
        self.part = part
        self._channel = part.channels[0]
        self._bare: RegisterTransport = transport
        self._bus: RegisterTransport = transport
        self.serial = serial
        self.endpoint = transport.endpoint
        self._clock = clock
        self._odr_hz = 10.0

    def _fault(self, message: str) -> InstrumentError:
        return InstrumentError(f"sensor {self.serial} ({self.endpoint}): {message}")

    # ------------------------------------------------------------------ the Sensor interface
    def identify(self) -> DeviceIdentity:
        return DeviceIdentity((self._bus.read(regs.REG_WHO_AM_I, 1)[0],))  # no revision register

    def reset(self) -> None:
        """SOFT_RST (CTRL_REG2), then wait with a deadline until the bit clears itself."""
        self._bus.write(regs.REG_CTRL2, regs.CTRL2_SOFT_RST)
        try:
            wait_until(self._clock, lambda: not self._bus.read(regs.REG_CTRL2, 1)[0] & regs.CTRL2_SOFT_RST,
                       timeout_s=RESET_TIMEOUT_S, poll_s=RESET_POLL_S,
                       what=f"sensor {self.serial} ({self.endpoint}) SOFT_RST to clear after a soft reset")
        except WaitTimeout as exc:
            raise InstrumentError(str(exc)) from None

    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        """Full scale and output data rate, the temperature sensor on, the z axis in the x and y axes' mode, block
        data update (a sample's low and high bytes from one conversion, as ST's polling example sets it);
        written and read back."""
        if self._channel.name not in ranges:
            raise self._fault(f"no range given for its {self._channel.name} channel")
        code = self.part.odr_code(odr_hz)
        wanted = (regs.ctrl1(code), regs.ctrl2(self._channel.range_codes[ranges[self._channel.name]]),
                  regs.ctrl3_current(self._bus.read(regs.REG_CTRL3, 1)[0]), regs.ctrl4(code), regs.CTRL5_BDU)
        self._bus.write(regs.REG_CTRL1, wanted[0])
        self._bus.write(regs.REG_CTRL2, wanted[1])
        self._bus.write(regs.REG_CTRL4, wanted[3])
        self._bus.write(regs.REG_CTRL5, wanted[4])
        readback = tuple(self._bus.read(regs.REG_CTRL1, 5))
        if readback != wanted:
            raise self._fault("CTRL_REG1…5 read back " + "/".join(f"{v:02X}" for v in readback) + ", not "
                              + "/".join(f"{v:02X}" for v in wanted))
        self._odr_hz = odr_hz

    def start_measurement(self) -> None:
        """Continuous conversion; wait out its turn-on."""
        self._bus.write(regs.REG_CTRL3, regs.CTRL3_CONTINUOUS)
        self._clock.sleep(TURN_ON_S)

    def standby(self) -> None:
        self._bus.write(regs.REG_CTRL3, regs.CTRL3_POWER_DOWN)

    def read_settings(self) -> tuple[dict[str, float], float]:
        """(its channel's range, the output data rate) as CTRL_REG1 and CTRL_REG2 hold them."""
        ctrl1, ctrl2 = self._bus.read(regs.REG_CTRL1, 2)
        by_code = {code: range_ for range_, code in self._channel.range_codes.items()}
        rate = self.part.odr_for_code(regs.rate_code_of(ctrl1))
        fs = regs.fs_of(ctrl2)
        if rate is None or fs not in by_code:
            raise self._fault(f"CTRL_REG1/CTRL_REG2 read {ctrl1:02X}/{ctrl2:02X}: no rate or range of the {self.part.label}")
        return {self._channel.name: by_code[fs]}, rate

    def read_temperature_c(self) -> float:
        """TEMP_OUT_L/H in one burst."""
        raw = self._bus.read(regs.REG_TEMP_OUT_L, 2)
        return float(self.part.temperature.celsius(int.from_bytes(raw, "little", signed=True)))

    def acquire(self, n_samples: int) -> SampleBlock:
        """`n_samples` consecutive samples, each read once ZYXDA says it is new."""
        raw, t_start = poll_block(self._clock, self._odr_hz, n_samples, self._read_sample, self._fault)
        _, field, temperature = regs.decode_samples(raw)
        celsius = self.part.temperature.celsius
        return SampleBlock({self._channel.name: field}, t_start, t_start + (n_samples - 1) / self._odr_hz,
                           (float(celsius(int(temperature[0]))), float(celsius(int(temperature[-1])))))

    def close(self) -> None:
        self._bus.close()

    def retry_exchanges(self, call: RetryCall) -> None:
        """Retry each register access on its own (a retried sample burst whose first reply was lost reads ZYXDA
        clear, so that sample is read as late and its block taken again)."""
        self._bus = RetryingTransport(self._bare, call)

    def reconnect(self) -> None:
        if isinstance(self._bare, Reconnecting):
            self._bare.reconnect()

    def _read_sample(self) -> tuple[bytes, bool]:
        """One burst STATUS…TEMP_OUT_H: (the sample, STATUS's ZYXDA, which reading the data clears)."""
        raw = self._bus.read(regs.REG_STATUS, regs.SAMPLE_BYTES)
        return raw, bool(raw[0] & regs.STATUS_ZYXDA)
