"""The ICM-42688-P's register map (user bank 0) and data format, as data: shared by the driver and the simulated
part so both agree on every bit. Ranges, sensitivities, rates and their codes are the part's facts
(`accelcal_rig.parts.icm42688`). Sources: docs/instruments.md, "TDK ICM-42688-P".
"""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------------- register map, bank 0
REG_DEVICE_CONFIG = 0x11
REG_FIFO_CONFIG = 0x16       # FIFO_MODE bits 7:6
REG_TEMP_DATA1 = 0x1D        # TEMP_DATA1 (high byte), TEMP_DATA0 at 0x1E
REG_ACCEL_DATA_X1 = 0x1F     # ACCEL_DATA_X1, X0, Y1, Y0, Z1, Z0: 0x1F…0x24
REG_GYRO_DATA_X1 = 0x25      # GYRO_DATA_X1 … GYRO_DATA_Z0: 0x25…0x2A
REG_GYRO_DATA_Z0 = 0x2A
REG_INT_STATUS = 0x2D
REG_FIFO_COUNTH = 0x2E       # FIFO_COUNTH, FIFO_COUNTL: read together, COUNTH first
REG_FIFO_DATA = 0x30         # the FIFO's read port: a burst from it stays on it
REG_SIGNAL_PATH_RESET = 0x4B
REG_INTF_CONFIG0 = 0x4C
REG_PWR_MGMT0 = 0x4E
REG_GYRO_CONFIG0 = 0x4F
REG_ACCEL_CONFIG0 = 0x50
REG_FIFO_CONFIG1 = 0x5F
REG_WHO_AM_I = 0x75
REG_BANK_SEL = 0x76          # in every bank
#: The last address as the project models bank 0 (the whole 7-bit space: the data sheet's map pages were not read).
REG_LAST = 0x7F
#: Bank 0's read-only registers the project knows: the data registers, INT_STATUS (and TMST_FSYNC between), the
#: FIFO's count and data port, WHO_AM_I.
READ_ONLY_REGISTERS = frozenset({*range(REG_TEMP_DATA1, REG_FIFO_DATA + 1), REG_WHO_AM_I})

DEVICE_CONFIG_SOFT_RESET = 0x01
INT_STATUS_RESET_DONE = 0x10
INT_STATUS_DATA_RDY = 0x08
INT_STATUS_FIFO_FULL = 0x02
#: PWR_MGMT0: GYRO_MODE (bits 3:2) and ACCEL_MODE (bits 1:0) low-noise (0b11); temperature on (bit 5 clear).
PWR_MGMT0_LOW_NOISE = 0x0F
PWR_MGMT0_OFF = 0x00
#: What a data register holds for a sensor that is off or has no sample yet.
DATA_INVALID = -32768

# ---------------------------------------------------------------------- the FIFO
#: FIFO_CONFIG's FIFO_MODE: stop-on-full (0b10 in bits 7:6): a full FIFO drops new samples and says so in
#: INT_STATUS's FIFO_FULL, so a lost sample is seen, never a silently older one.
FIFO_MODE_STOP_ON_FULL = 0x80
FIFO_MODE_BYPASS = 0x00
#: FIFO_CONFIG1: accelerometer, gyroscope and temperature in each packet: packet 3, 16 bytes.
FIFO_CONFIG1_ACCEL_GYRO_TEMP = 0x07
#: SIGNAL_PATH_RESET's FIFO_FLUSH (write-to-clear).
SIGNAL_PATH_RESET_FIFO_FLUSH = 0x02
#: INTF_CONFIG0 at reset: the FIFO count in bytes, it and the data big-endian (the only setting modelled).
INTF_CONFIG0_RESET = 0x30
#: The FIFO's size in bytes, and how many 16-byte packets that holds.
FIFO_BYTES = 2048
PACKET_BYTES = 16
FIFO_PACKETS = FIFO_BYTES // PACKET_BYTES
#: A packet's header: bit 7 says the FIFO is empty; accelerometer (bit 6), gyroscope (bit 5) and an ODR
#: timestamp (bits 3:2 = 0b10) make packet 3; bits 1:0 flag a rate change and are ignored.
HEADER_EMPTY = 0x80
PACKET3_HEADER = 0x68
PACKET3_HEADER_MASK = 0xFC
#: The packet's 8-bit temperature: °C = FIFO_TEMP_DATA / 2.07 + 25, 64 times coarser than TEMP_DATA's 132.48.
FIFO_TEMPERATURE_SCALE = 64

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


def decode_packets(raw: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Packet-3 FIFO packets, back to back → (accel codes (n, 3), gyro codes (n, 3), each packet's temperature in
    TEMP_DATA's codes (n,)); ValueError names a packet whose header is not packet 3's (out of step, or empty)."""
    if len(raw) % PACKET_BYTES:
        raise ValueError(f"{len(raw)} bytes are not whole {PACKET_BYTES}-byte FIFO packets")
    packets = np.frombuffer(raw, dtype=np.uint8).reshape(-1, PACKET_BYTES)
    wrong = np.flatnonzero((packets[:, 0] & PACKET3_HEADER_MASK) != PACKET3_HEADER)
    if wrong.size:
        raise ValueError(f"FIFO packet {int(wrong[0])} has header 0x{int(packets[wrong[0], 0]):02X}, not packet 3's "
                         f"0x{PACKET3_HEADER:02X}")
    words = np.ascontiguousarray(packets[:, 1:13]).view(">i2").astype(np.int32)
    temperature = packets[:, 13].view(np.int8).astype(np.int32) * FIFO_TEMPERATURE_SCALE
    return words[:, 0:3], words[:, 3:6], temperature


def encode_packets(accel: np.ndarray, gyro: np.ndarray, temperature: np.ndarray, timestamp: np.ndarray) -> bytes:
    """What the part writes to its FIFO for samples with these codes (for simulators): packet 3, `temperature` in
    TEMP_DATA's codes (rounded to the packet's 8 bits), `timestamp` the 16-bit field."""
    n = len(accel)
    packets = np.empty((n, PACKET_BYTES), dtype=np.uint8)
    packets[:, 0] = PACKET3_HEADER
    words = np.clip(np.concatenate([np.asarray(accel).reshape(n, 3), np.asarray(gyro).reshape(n, 3)], axis=1),
                    -32768, 32767)
    packets[:, 1:13] = words.astype(">i2").view(np.uint8).reshape(n, 12)
    packets[:, 13] = np.clip(np.rint(np.asarray(temperature) / FIFO_TEMPERATURE_SCALE), -128, 127).astype(np.int8).view(np.uint8)
    packets[:, 14:16] = (np.asarray(timestamp, dtype=np.int64) & 0xFFFF).astype(">u2").view(np.uint8).reshape(n, 2)
    return packets.tobytes()


def encode_sample(temperature: int, accel: np.ndarray, gyro: np.ndarray) -> bytes:
    """What the part's data registers hold for one sample (for simulators)."""
    words = np.concatenate([[temperature], np.asarray(accel).reshape(3), np.asarray(gyro).reshape(3)])
    return np.clip(words, -32768, 32767).astype(">i2").tobytes()
