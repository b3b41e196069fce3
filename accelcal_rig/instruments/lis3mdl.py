"""The LIS3MDL's register map and data format, as data: shared by the driver and the simulated part so both
agree on every bit. Ranges, sensitivities, rates and their codes are the part's facts
(`accelcal_rig.parts.lis3mdl`). Sources: docs/instruments.md, "ST LIS3MDL" (data sheet DS9463 Rev 7 §6–7).
"""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------------- register map
REG_OFFSET_X_L = 0x05        # OFFSET_X/Y/Z_REG_L/H: 0x05…0x0A (Rev 7; reserved before)
REG_WHO_AM_I = 0x0F
REG_CTRL1 = 0x20             # TEMP_EN (7), OM (6:5), DO (4:2), FAST_ODR (1), ST (0)
REG_CTRL2 = 0x21             # FS (6:5), REBOOT (3), SOFT_RST (2)
REG_CTRL3 = 0x22             # LP (5), SIM (2), MD (1:0)
REG_CTRL4 = 0x23             # OMZ (3:2), BLE (1)
REG_CTRL5 = 0x24             # FAST_READ (7), BDU (6)
REG_STATUS = 0x27            # ZYXOR … XOR (7:4), ZYXDA … XDA (3:0)
REG_OUT_X_L = 0x28           # OUT_X_L, OUT_X_H, OUT_Y_L, OUT_Y_H, OUT_Z_L, OUT_Z_H: 0x28…0x2D
REG_TEMP_OUT_L = 0x2E        # TEMP_OUT_L, TEMP_OUT_H
REG_INT_CFG = 0x30
REG_INT_SRC = 0x31
REG_INT_THS_H = 0x33
#: The last register of the map.
REG_LAST = REG_INT_THS_H
#: Read-only registers: WHO_AM_I, STATUS, the data registers, INT_SRC.
READ_ONLY_REGISTERS = frozenset({REG_WHO_AM_I, *range(REG_STATUS, REG_TEMP_OUT_L + 2), REG_INT_SRC})
#: Reserved addresses ("do not write": the data sheet says a write may damage the part): the driver never
#: writes them; the simulated part ignores a write there.
RESERVED = frozenset({*range(0x00, 0x05), *range(0x0B, 0x0F), *range(0x10, 0x20), 0x25, 0x26})

#: Reset values of the registers that have one other than 0.
RESET_VALUES = {REG_WHO_AM_I: 0x3D, REG_CTRL1: 0x10, REG_CTRL3: 0x03, REG_INT_CFG: 0xE8}

CTRL1_TEMP_EN = 0x80
#: CTRL_REG5 BDU (bit 6): the output registers not updated until both bytes of a sample were read.
CTRL5_BDU = 0x40
CTRL2_SOFT_RST = 0x04
#: CTRL_REG3 MD (bits 1:0): 00 continuous conversion; 11 (or 10) power-down, the reset state.
CTRL3_CONTINUOUS = 0x00
CTRL3_POWER_DOWN = 0x03
STATUS_ZYXDA = 0x08
STATUS_ZYXOR = 0x80
#: CTRL_REG4 BLE (bit 1): 1 puts the high byte first.
CTRL4_BLE = 0x02

#: One sample in one burst: STATUS, OUT_X_L … OUT_Z_H, TEMP_OUT_L, TEMP_OUT_H (0x27…0x2F).
SAMPLE_BYTES = REG_TEMP_OUT_L + 2 - REG_STATUS


def ctrl1(rate_code: int, temperature: bool = True) -> int:
    """CTRL_REG1 of a rate's packed code (OM, DO, FAST_ODR: bits 6:1), the temperature sensor on or off."""
    return (CTRL1_TEMP_EN if temperature else 0) | (rate_code & 0x3F) << 1


def rate_code_of(ctrl1_value: int) -> int:
    """The packed rate code (OM, DO, FAST_ODR) CTRL_REG1 holds."""
    return (ctrl1_value >> 1) & 0x3F


def ctrl4(rate_code: int) -> int:
    """CTRL_REG4 with the z axis in the x and y axes' operating mode (OMZ = OM), little-endian data."""
    return ((rate_code >> 4) & 0x03) << 2


def ctrl3_current(ctrl3_value: int) -> int:
    """CTRL_REG3 as a configuration leaves it (the mode it holds: configuring neither starts nor stops the
    part)."""
    return ctrl3_value & 0x27


def ctrl2(fs: int) -> int:
    """CTRL_REG2 with full scale FS (0 ±4 … 3 ±16 gauss)."""
    return (fs & 0x03) << 5


def fs_of(ctrl2_value: int) -> int:
    return (ctrl2_value >> 5) & 0x03


def decode_samples(raw: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bursts of SAMPLE_BYTES back to back → (STATUS (n,), field codes (n, 3), temperature codes (n,)), the
    16-bit words little-endian (CTRL_REG4 BLE 0)."""
    rows = np.frombuffer(raw, dtype=np.uint8).reshape(-1, SAMPLE_BYTES)
    words = rows[:, 1:].copy().view("<i2").astype(np.int32)
    return rows[:, 0].astype(np.int32), words[:, 0:3], words[:, 3]


def encode_words(words: np.ndarray, big_endian: bool = False) -> bytes:
    """What the data registers hold for 16-bit words (for simulators)."""
    return np.clip(np.asarray(words), -32768, 32767).astype(">i2" if big_endian else "<i2").tobytes()
