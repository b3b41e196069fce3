"""What a sensor part is, as the rig needs to know it: the one place a part's facts live.

A part is data: the channels it measures (each a quantity on three axes, in a unit, with its sensitivity
per range), its identity registers, its data rates, its own temperature sensor, and the driver that speaks
it. The identity check, the procedure's range and data-rate validation, the driver's register writes, the
simulator, the store and the fit all read a part's facts from here; a new part is a new table.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class TemperatureFormat:
    """The part's own (uncalibrated) temperature sensor: raw = intercept + slope × (T − reference)."""

    bits: int
    intercept_lsb: float
    slope_lsb_per_c: float
    reference_c: float = 25.0
    signed: bool = False                       #: two's complement codes (an ICM-42688-P's), else unsigned

    def celsius(self, raw: np.ndarray | int) -> np.ndarray | float:
        """Raw reading → °C."""
        return self.reference_c + (np.asarray(raw, dtype=float) - self.intercept_lsb) / self.slope_lsb_per_c

    def from_registers(self, high: int, low: int) -> int:
        """The code its two temperature registers hold (high byte first): the low `bits` of the pair, sign-extended
        where the code is signed (an ADXL355's TEMP2 nibble and TEMP1; an ICM-42688-P's TEMP_DATA1, TEMP_DATA0)."""
        code = ((high << 8) | low) & ((1 << self.bits) - 1)
        return code - (1 << self.bits) if self.signed and code >> (self.bits - 1) else code

    def raw(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """°C → what the part reports: rounded and clipped to its code width."""
        raw = self.intercept_lsb + self.slope_lsb_per_c * (np.asarray(temperature_c, dtype=float) - self.reference_c)
        low, high = (-(1 << (self.bits - 1)), (1 << (self.bits - 1)) - 1) if self.signed else (0, (1 << self.bits) - 1)
        return np.clip(np.rint(raw), low, high).astype(np.int32)


@dataclass(frozen=True)
class Channel:
    """One quantity a part measures on its axes: what acquisition, the store, the fit and the outputs iterate.
    Ranges are the ± full scale in the channel's unit, as a procedure's acquisition gives them: whole numbers
    where the data sheet's are (±2 g, ±2000 °/s), fractions where not (±15.625 °/s); a lookup by 2.0 finds 2."""

    name: str                                  #: the key everything downstream uses: "accel", "gyro"
    quantity: str                              #: "acceleration", "angular rate"
    unit: str                                  #: "g", "dps" (°/s)
    # Keyed by range (a float; tables write whole ranges as ints, and a Mapping's key type is invariant, so the
    # keys are typed Any: {2: …} and {15.625: …} are both tables of float ranges).
    lsb_per_unit: Mapping[Any, float]          #: range → nominal sensitivity
    range_codes: Mapping[Any, int]             #: range → the part's register code for it
    code_bits: int                             #: codes are signed, this wide
    noise_density_micro_per_rthz: float        #: typical, in µ(unit)/√Hz (µg/√Hz, µ°/s/√Hz), most sensitive range
    axes: tuple[str, ...] = ("x", "y", "z")
    zero_offset: float | None = None           #: the data sheet's ± range of the zero offset at 25 °C, in unit
    #: The range a procedure that names none runs the channel at: the part's own power-on range where a channel
    #: has one the whole fixture can share (a magnetometer's beside accelerometers); None: the procedure names it.
    default_range: float | None = None

    @property
    def ranges(self) -> tuple[float, ...]:
        return tuple(sorted(self.lsb_per_unit))

    @property
    def code_min(self) -> int:
        return -(1 << (self.code_bits - 1))

    @property
    def code_max(self) -> int:
        return (1 << (self.code_bits - 1)) - 1

    def lsb(self, range_: float) -> float:
        """Size of one code in the channel's unit on a range."""
        return 1.0 / self.lsb_per_unit[range_]

    def quantise(self, values: np.ndarray, range_: float) -> np.ndarray:
        """Values in the channel's unit → signed codes as the ADC would output them (rounded, saturating)."""
        codes = np.rint(np.asarray(values, dtype=float) * self.lsb_per_unit[range_])
        return np.clip(codes, self.code_min, self.code_max).astype(np.int32)

    def range_problem(self, range_: float, label: str) -> str | None:
        """Why ±`range_` is not a range of this channel of the part `label`; None when it is."""
        if range_ in self.lsb_per_unit:
            return None
        return (f"±{range_:g} {self.unit} is not a range of the {label} "
                f"(±{'/'.join(f'{r:g}' for r in self.ranges)} {self.unit})")


@dataclass(frozen=True)
class SpiFraming:
    """How the part's SPI command byte carries a register address and the read bit (mode 0, the address
    first, then the data): an ADXL355 reads with (address << 1) | 1; an ICM-42688-P with address | 0x80; an
    LIS3MDL with address | 0x80, and 0x40 more to read several registers in one burst."""

    address_shift: int
    read_bit: int
    #: set in the command byte of a read of more than one register (0: every burst increments)
    burst_bit: int = 0
    #: the SPI mode (clock polarity and phase) the part's data sheet draws: 0 (clock idle low), 3 (idle high)
    mode: int = 0

    def read_command(self, address: int, count: int = 1) -> int:
        return (address << self.address_shift) | self.read_bit | (self.burst_bit if count > 1 else 0)

    def write_command(self, address: int) -> int:
        return address << self.address_shift


@dataclass(frozen=True)
class Part:
    """One part's facts."""

    name: str                                  #: what a rig config's `part:` says, e.g. "adxl357"
    label: str                                 #: how people write it, e.g. "ADXL357"
    identity: tuple[int, ...]                  #: identification registers, as its driver reads them
    identity_names: tuple[str, ...]            #: their names in the data sheet, e.g. ("WHO_AM_I",)
    channels: tuple[Channel, ...]              #: what it measures, the first its primary channel
    output_data_rates_hz: tuple[float, ...]    #: by the part's ODR register code 0, 1, … (or `odr_codes`)
    temperature: TemperatureFormat
    source: str                                #: where these facts come from
    #: The driver that speaks it ("module:attribute" of a class built as `Device(transport, serial, clock,
    #: part)`): the device is built from the part, never by a caller naming a part's class.
    device: str = "accelcal_rig.instruments.adxl355_driver:Adxl355"
    #: Each rate's register code where it is not the rate's index in `output_data_rates_hz`.
    odr_codes: tuple[int, ...] | None = None
    #: A dry run's simulated part behind a serial bridge ("module:attribute" of a factory
    #: `(lab, sensor config, faults) -> served instrument`).
    simulator: str = "accelcal_rig.sim.adxl355_bridge_server:serve_bridge"
    #: Its SPI command framing, for a host on the bus itself (spidev); the ADXL35x's by default.
    spi: SpiFraming = SpiFraming(address_shift=1, read_bit=0x01)
    #: Bytes of one sample as its FIFO gives it, which a bridge's capture returns as read (an ADXL35x's three
    #: 3-byte entries; an ICM-42688-P's 16-byte packet).
    fifo_sample_bytes: int = 9

    def channel(self, name: str) -> Channel:
        """The channel called `name`; KeyError naming the ones the part has."""
        for channel in self.channels:
            if channel.name == name:
                return channel
        raise KeyError(f"the {self.label} has no {name!r} channel ({', '.join(self.channel_names)})")

    @property
    def channel_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.channels)

    def odr_code(self, odr_hz: float) -> int:
        """The part's code for an output data rate (the nearest one)."""
        index = int(np.argmin(np.abs(np.array(self.output_data_rates_hz) - odr_hz)))
        return index if self.odr_codes is None else self.odr_codes[index]

    def odr_for_code(self, code: int) -> float | None:
        """The output data rate of register code `code`; None for a code that is no rate of the part."""
        codes = self.odr_codes if self.odr_codes is not None else tuple(range(len(self.output_data_rates_hz)))
        return self.output_data_rates_hz[codes.index(code)] if code in codes else None

    def has_rate(self, odr_hz: float) -> bool:
        return any(abs(odr_hz - rate) < 1e-3 for rate in self.output_data_rates_hz)

    def rate_for(self, odr_hz: float) -> float | None:
        """The rate this part runs at when a procedure asks for `odr_hz`: that rate where the part has it, else its
        next faster one (a mixed fixture's parts rarely share every rate; sampling faster only shortens a pose's
        block); None when the part has no rate that fast."""
        if self.has_rate(odr_hz):
            return odr_hz
        faster = [rate for rate in self.output_data_rates_hz if rate > odr_hz]
        return min(faster) if faster else None

    def range_problem(self, channel: str, range_: float) -> str | None:
        """Why ±`range_` is not a range of the part's `channel`; None when it is."""
        return self.channel(channel).range_problem(range_, self.label)

    def rate_problem(self, odr_hz: float) -> str | None:
        """Why the part cannot run at `odr_hz` or its next faster rate; None when it can."""
        if self.rate_for(odr_hz) is not None:
            return None
        rates = ", ".join(f"{r:g}" for r in self.output_data_rates_hz)
        return f"{odr_hz:g} Hz is faster than every {self.label} output data rate ({rates})"

    def describe_identity(self, found: tuple[int, ...]) -> str:
        """Identification registers as the data sheet names them: "DEVID_AD 0xAD, DEVID_MST 0x1D, …"."""
        return ", ".join(f"{name} 0x{value:02X}" for name, value in zip(self.identity_names, found))

    def describe_ranges(self, ranges: Mapping[str, float]) -> str:
        """Each channel's range: "±2 g", "±4 g, ±2000 dps"."""
        return ", ".join(f"±{ranges[c.name]:g} {c.unit}" for c in self.channels if c.name in ranges)

    def wrong_identity(self, found: tuple[int, ...]) -> str | None:
        """Why identification registers `found` are not this part's; None when they are."""
        if tuple(found) == self.identity:
            return None
        return f"identity {_hex(found)} is not an {self.label} ({_hex(self.identity)})"


def _hex(values: tuple[int, ...]) -> str:
    return "/".join(f"{v:02X}" for v in values)


def odr_hz_of(part: Part, asked_hz: float) -> float:
    """The rate `part` runs at when a procedure asks for `asked_hz` (`Part.rate_for`); the procedure's check
    refused a rate no DUT part reaches before anything runs."""
    rate = part.rate_for(asked_hz)
    if rate is None:
        raise ValueError(part.rate_problem(asked_hz))
    return rate
