"""ADXL355 datasheet facts: identity, ranges, output data rates, data and temperature formats.

Shared by the driver side and the simulator so both agree on every bit.
"""

from __future__ import annotations

import numpy as np

DEVID_AD = 0xAD
DEVID_MST = 0x1D
PARTID = 0xED

#: Nominal sensitivity per range setting (datasheet): ±2 g is 256 000 LSB/g.
RANGE_LSB_PER_G: dict[int, float] = {2: 256_000.0, 4: 128_000.0, 8: 64_000.0}

#: ODR_LPF codes 0..10 of the FILTER register, in Hz; the low-pass corner is ODR/4.
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (
    4000.0, 2000.0, 1000.0, 500.0, 250.0, 125.0, 62.5, 31.25, 15.625, 7.813, 3.906,
)

CODE_MIN = -(1 << 19)
CODE_MAX = (1 << 19) - 1

TEMPERATURE_INTERCEPT_LSB = 1885.0
TEMPERATURE_SLOPE_LSB_PER_C = -9.05
TEMPERATURE_REFERENCE_C = 25.0


def lsb_g(range_g: int) -> float:
    """Size of one 20-bit code in g for a range setting."""
    return 1.0 / RANGE_LSB_PER_G[range_g]


def temperature_c_from_raw(raw: np.ndarray | int) -> np.ndarray | float:
    """12-bit TEMP2:TEMP1 reading → °C (datasheet: 1885 LSB at 25 °C, −9.05 LSB/°C)."""
    return TEMPERATURE_REFERENCE_C + (np.asarray(raw, dtype=float) - TEMPERATURE_INTERCEPT_LSB) / (
        TEMPERATURE_SLOPE_LSB_PER_C
    )


def raw_from_temperature_c(temperature_c: np.ndarray | float) -> np.ndarray:
    """Inverse of `temperature_c_from_raw`, rounded and clipped to 12 bits (what the sensor reports)."""
    raw = TEMPERATURE_INTERCEPT_LSB + TEMPERATURE_SLOPE_LSB_PER_C * (
        np.asarray(temperature_c, dtype=float) - TEMPERATURE_REFERENCE_C
    )
    return np.clip(np.rint(raw), 0, 4095).astype(np.int32)


def quantise_g(accel_g: np.ndarray, range_g: int) -> np.ndarray:
    """Acceleration in g → signed 20-bit codes as the ADC would output them (rounded, saturating)."""
    codes = np.rint(np.asarray(accel_g, dtype=float) * RANGE_LSB_PER_G[range_g])
    return np.clip(codes, CODE_MIN, CODE_MAX).astype(np.int32)
