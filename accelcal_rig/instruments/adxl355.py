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


def raw_temperature(temp2: int, temp1: int) -> int:
    """TEMP2 (low nibble: bits 11..8) and TEMP1 (bits 7..0) → the 12-bit raw temperature."""
    return ((temp2 & 0x0F) << 8) | temp1


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


# ---------------------------------------------------------------------- register map
REG_DEVID_AD = 0x00
REG_STATUS = 0x04
REG_FIFO_ENTRIES = 0x05
REG_TEMP2 = 0x06
REG_FIFO_DATA = 0x11
REG_FILTER = 0x28
REG_FIFO_SAMPLES = 0x29
REG_RANGE = 0x2C
REG_POWER_CTL = 0x2D
REG_RESET = 0x2F

IDENTITY = (DEVID_AD, DEVID_MST, PARTID)

RESET_CODE = 0x52
STATUS_NVM_BUSY = 0x10
STATUS_FIFO_OVR = 0x04
STATUS_DATA_RDY = 0x01
POWER_CTL_STANDBY = 0x01
RANGE_CODES: dict[int, int] = {2: 0b01, 4: 0b10, 8: 0b11}
FIFO_CAPACITY_ENTRIES = 96  # one entry is one axis: 32 xyz samples

_ENTRY_X_MARKER = 0x01
_ENTRY_EMPTY = 0x02


def wrong_identity(found: tuple[int, int, int]) -> str | None:
    """Why identification registers (DEVID_AD, DEVID_MST, PARTID) are not an ADXL355's; None when they are."""
    if tuple(found) == IDENTITY:
        return None
    return f"identity {_hex(found)} is not an ADXL355 ({_hex(IDENTITY)})"


def _hex(values: tuple[int, ...]) -> str:
    return "/".join(f"{v:02X}" for v in values)


def odr_code(odr_hz: float) -> int:
    """FILTER register ODR_LPF code for an output data rate."""
    return int(np.argmin(np.abs(np.array(OUTPUT_DATA_RATES_HZ) - odr_hz)))


def decode_data_bytes(raw: bytes) -> np.ndarray:
    """3-byte big-endian fields, 20-bit two's complement left-justified → signed codes (vectorised)."""
    triplets = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3).astype(np.int32)
    codes = (triplets[:, 0] << 12) | (triplets[:, 1] << 4) | (triplets[:, 2] >> 4)
    return np.where(codes & 0x80000, codes - (1 << 20), codes).astype(np.int32)


def decode_fifo(raw: bytes, carried: bytes = b"") -> tuple[np.ndarray, bytes]:
    """FIFO entries (3 bytes each) → ((n, 3) codes, entries of an incomplete trailing sample).

    Empty entries are dropped and the stream is resynchronised on the X marker. Pass the returned tail
    as `carried` with the next burst, so a sample the part was still writing is completed, not lost.
    """
    entries = np.frombuffer(carried + raw, dtype=np.uint8).reshape(-1, 3)
    entries = entries[(entries[:, 2] & _ENTRY_EMPTY) == 0]
    x_marks = np.flatnonzero(entries[:, 2] & _ENTRY_X_MARKER)
    if x_marks.size == 0:
        return np.empty((0, 3), dtype=np.int32), b""
    entries = entries[x_marks[0]:]
    whole = entries.shape[0] // 3 * 3
    return decode_data_bytes(entries[:whole].tobytes()).reshape(-1, 3), entries[whole:].tobytes()


def encode_fifo(codes_xyz: np.ndarray) -> bytes:
    """(n, 3) codes → FIFO entry bytes, X entries marked (what the part puts out; for simulators)."""
    codes = np.asarray(codes_xyz, dtype=np.int64).reshape(-1) & 0xFFFFF
    entries = np.empty((codes.size, 3), dtype=np.uint8)
    entries[:, 0] = codes >> 12
    entries[:, 1] = (codes >> 4) & 0xFF
    entries[:, 2] = (codes & 0x0F) << 4
    entries[0::3, 2] |= _ENTRY_X_MARKER
    return entries.tobytes()


def empty_fifo_entries(count: int) -> bytes:
    """What reading an empty FIFO returns: entries with the empty flag set."""
    return bytes([0, 0, _ENTRY_EMPTY] * count)
