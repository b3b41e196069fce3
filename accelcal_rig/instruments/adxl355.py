"""The register map and data formats of the ADXL355 and its register-compatible siblings (ADXL357,
ADXL359): what differs between them — identity, ranges, sensitivity, temperature intercept — is in
`accelcal_rig.parts`. Shared by the driver side and the simulator so both agree on every bit.
"""

from __future__ import annotations

import numpy as np

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
#: The last register of the map (RESET).
REG_LAST = REG_RESET
#: Identity, STATUS, FIFO_ENTRIES, TEMP2/TEMP1, the data registers, FIFO_DATA and the reserved 0x12…0x1D: read-only.
READ_ONLY_REGISTERS = frozenset(range(0x00, 0x1E))
#: Written only in standby (the data sheet: change FILTER and RANGE only in standby).
STANDBY_ONLY_REGISTERS = frozenset({REG_FILTER, REG_RANGE})

RESET_CODE = 0x52
STATUS_NVM_BUSY = 0x10
STATUS_FIFO_OVR = 0x04
STATUS_DATA_RDY = 0x01
POWER_CTL_STANDBY = 0x01
FIFO_CAPACITY_ENTRIES = 96  # one entry is one axis: 32 xyz samples

_ENTRY_X_MARKER = 0x01
_ENTRY_EMPTY = 0x02


def raw_temperature(temp2: int, temp1: int) -> int:
    """TEMP2 (low nibble: bits 11..8) and TEMP1 (bits 7..0) → the 12-bit raw temperature."""
    return ((temp2 & 0x0F) << 8) | temp1


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
