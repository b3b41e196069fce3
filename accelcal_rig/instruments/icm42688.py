"""The ICM-42688-P's register map (user bank 0) and data format, as data: shared by the driver and the simulated
part so both agree on every bit. Ranges, sensitivities, rates and their codes are the part's facts
(`accelcal_rig.parts.icm42688`). Sources: docs/instruments.md, "TDK ICM-42688-P".
"""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------------- register map, bank 0
REG_DEVICE_CONFIG = 0x11
REG_TEMP_DATA1 = 0x1D        # TEMP_DATA1 (high byte), TEMP_DATA0 at 0x1E
REG_ACCEL_DATA_X1 = 0x1F     # ACCEL_DATA_X1, X0, Y1, Y0, Z1, Z0: 0x1F…0x24
REG_GYRO_DATA_X1 = 0x25      # GYRO_DATA_X1 … GYRO_DATA_Z0: 0x25…0x2A
REG_GYRO_DATA_Z0 = 0x2A
REG_INT_STATUS = 0x2D
REG_PWR_MGMT0 = 0x4E
REG_GYRO_CONFIG0 = 0x4F
REG_ACCEL_CONFIG0 = 0x50
REG_WHO_AM_I = 0x75
REG_BANK_SEL = 0x76          # in every bank
#: The last address as the project models bank 0 (the whole 7-bit space: the data sheet's map pages were not read).
REG_LAST = 0x7F
#: Bank 0's read-only registers the project knows: the data registers, INT_STATUS (and TMST_FSYNC between), WHO_AM_I.
READ_ONLY_REGISTERS = frozenset({*range(REG_TEMP_DATA1, REG_INT_STATUS + 1), REG_WHO_AM_I})

DEVICE_CONFIG_SOFT_RESET = 0x01
INT_STATUS_RESET_DONE = 0x10
INT_STATUS_DATA_RDY = 0x08
#: PWR_MGMT0: GYRO_MODE (bits 3:2) and ACCEL_MODE (bits 1:0) low-noise (0b11); temperature on (bit 5 clear).
PWR_MGMT0_LOW_NOISE = 0x0F
PWR_MGMT0_OFF = 0x00
#: What a data register holds for a sensor that is off or has no sample yet.
DATA_INVALID = -32768

#: One sample in one burst: TEMP_DATA1 up to GYRO_DATA_Z0, 7 big-endian 16-bit words.
SAMPLE_BYTES = REG_GYRO_DATA_Z0 - REG_TEMP_DATA1 + 1
#: The burst that also takes INT_STATUS (0x2B, 0x2C are TMST_FSYNCH/L, read and ignored).
SAMPLE_AND_STATUS_BYTES = REG_INT_STATUS - REG_TEMP_DATA1 + 1

#: SPI: the first byte's bit 7 is 1 for a read, 0 for a write; the address is bits 6:0.
SPI_READ = 0x80


def config0(fs_sel: int, odr_code: int) -> int:
    """ACCEL_CONFIG0 / GYRO_CONFIG0: FS_SEL in bits 7:5, ODR in bits 3:0."""
    return (fs_sel & 0x07) << 5 | (odr_code & 0x0F)


def split_config0(value: int) -> tuple[int, int]:
    """ACCEL_CONFIG0 / GYRO_CONFIG0 → (FS_SEL, ODR code)."""
    return (value >> 5) & 0x07, value & 0x0F


def decode_words(raw: bytes) -> np.ndarray:
    """Big-endian 16-bit two's complement words → int32 codes (vectorised)."""
    return np.frombuffer(raw, dtype=">i2").astype(np.int32)


def decode_samples(raw: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bursts of SAMPLE_BYTES, back to back → (temperature codes (n,), accel codes (n, 3), gyro codes (n, 3))."""
    words = decode_words(raw).reshape(-1, 7)
    return words[:, 0], words[:, 1:4], words[:, 4:7]


def encode_sample(temperature: int, accel: np.ndarray, gyro: np.ndarray) -> bytes:
    """What the part's data registers hold for one sample (for simulators)."""
    words = np.concatenate([[temperature], np.asarray(accel).reshape(3), np.asarray(gyro).reshape(3)])
    return np.clip(words, -32768, 32767).astype(">i2").tobytes()
