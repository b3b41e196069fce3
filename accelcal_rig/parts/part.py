"""What a digital accelerometer part is, as the rig needs to know it: the one place a part's facts live.

The identity check, the procedure's range and data-rate validation, the driver's register writes, the
simulator and the fit all read a part's facts from its `AccelerometerPart`; a new part is a new table.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TemperatureFormat:
    """The part's own (uncalibrated) temperature sensor: raw = intercept + slope × (T − reference)."""

    bits: int
    intercept_lsb: float
    slope_lsb_per_c: float
    reference_c: float = 25.0

    def celsius(self, raw: np.ndarray | int) -> np.ndarray | float:
        """Raw reading → °C."""
        return self.reference_c + (np.asarray(raw, dtype=float) - self.intercept_lsb) / self.slope_lsb_per_c

    def raw(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """°C → what the part reports: rounded and clipped to its code width."""
        raw = self.intercept_lsb + self.slope_lsb_per_c * (np.asarray(temperature_c, dtype=float) - self.reference_c)
        return np.clip(np.rint(raw), 0, (1 << self.bits) - 1).astype(np.int32)


@dataclass(frozen=True)
class AccelerometerPart:
    """One part's facts. Ranges are the ± full scale in g, as a procedure's `acquisition.range_g` gives them."""

    name: str                                  #: what a rig config's `part:` says, e.g. "adxl357"
    label: str                                 #: how people write it, e.g. "ADXL357"
    identity: tuple[int, int, int]             #: identification registers: DEVID_AD, DEVID_MST, PARTID
    lsb_per_g: Mapping[int, float]             #: range → nominal sensitivity
    range_codes: Mapping[int, int]             #: range → the RANGE register's code
    output_data_rates_hz: tuple[float, ...]    #: by the FILTER register's ODR code 0, 1, …
    code_bits: int                             #: acceleration codes are signed, this wide
    temperature: TemperatureFormat
    noise_density_ug_per_rthz: float           #: typical, on its most sensitive range
    source: str                                #: where these facts come from
    zero_g_offset_mg: float | None = None      #: the data sheet's ± range of the 0 g offset at 25 °C, if known

    @property
    def ranges_g(self) -> tuple[int, ...]:
        return tuple(sorted(self.lsb_per_g))

    @property
    def code_min(self) -> int:
        return -(1 << (self.code_bits - 1))

    @property
    def code_max(self) -> int:
        return (1 << (self.code_bits - 1)) - 1

    def lsb_g(self, range_g: int) -> float:
        """Size of one acceleration code in g on a range."""
        return 1.0 / self.lsb_per_g[range_g]

    def quantise_g(self, accel_g: np.ndarray, range_g: int) -> np.ndarray:
        """Acceleration in g → signed codes as the ADC would output them (rounded, saturating)."""
        codes = np.rint(np.asarray(accel_g, dtype=float) * self.lsb_per_g[range_g])
        return np.clip(codes, self.code_min, self.code_max).astype(np.int32)

    def odr_code(self, odr_hz: float) -> int:
        """The FILTER register's code for an output data rate (the nearest one)."""
        return int(np.argmin(np.abs(np.array(self.output_data_rates_hz) - odr_hz)))

    def has_rate(self, odr_hz: float) -> bool:
        return any(abs(odr_hz - rate) < 1e-3 for rate in self.output_data_rates_hz)

    def range_problem(self, range_g: int) -> str | None:
        """Why ±`range_g` g is not a range of this part; None when it is."""
        if range_g in self.lsb_per_g:
            return None
        return f"±{range_g:g} g is not a range of the {self.label} (±{'/'.join(map(str, self.ranges_g))} g)"

    def rate_problem(self, odr_hz: float) -> str | None:
        """Why `odr_hz` is not an output data rate of this part; None when it is."""
        if self.has_rate(odr_hz):
            return None
        rates = ", ".join(f"{r:g}" for r in self.output_data_rates_hz)
        return f"{odr_hz:g} Hz is not an {self.label} output data rate ({rates})"

    def wrong_identity(self, found: tuple[int, int, int]) -> str | None:
        """Why identification registers `found` are not this part's; None when they are."""
        if tuple(found) == self.identity:
            return None
        return f"identity {_hex(found)} is not an {self.label} ({_hex(self.identity)})"


def _hex(values: tuple[int, ...]) -> str:
    return "/".join(f"{v:02X}" for v in values)
