"""The campaign journal: an append-only, checksummed, fsync'd log of records, the durable truth of a campaign.

A record on disk is `ACJ1 | payload length (u32) | CRC-32 of the payload (u32) | payload`, little-endian;
the payload is a JSON head (`kind`, `meta`, and the name, dtype and shape of each array) followed by
the arrays' raw bytes, so numbers come back bit for bit. Bytes once acknowledged are never written again:
the writer only appends, at the end of the last whole record, into space it has allocated ahead
(zeros), keeping a reserve so the records that stop a campaign still fit when the disk is full.

Reading tolerates anything: a record cut short by a kill (the tail), zeroed or flipped bytes (a
stretch that fails its checksum, skipped to the next record that passes), a foreign file (no records).
"""

from __future__ import annotations

import json
import math
import os
import struct
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from accelcal_rig.durable import (
    disk_errors,
    fsync_directory,
    is_disk_full,
    temporary_beside,
    unused_name,
    write_all,
    write_atomically,
)
from accelcal_rig.errors import ConfigError, DiskFull

MAGIC = b"ACJ1"
_HEAD = struct.Struct("<4sII")
_META_LENGTH = struct.Struct("<I")
#: Allocation grows by this much at a time (fewer allocations, a full disk found early).
ALLOCATION_CHUNK_BYTES = 1 << 20
#: Array element types a record may hold (anything else marks the record as damaged).
_DTYPE_KINDS = frozenset("fiub")
_sync = getattr(os, "fdatasync", os.fsync)


def encode_record(kind: str, meta: dict[str, Any], arrays: dict[str, np.ndarray] | None = None) -> bytes:
    arrays = {name: np.ascontiguousarray(value) for name, value in (arrays or {}).items()}
    head = {"kind": kind, "meta": meta, "arrays": [[n, a.dtype.str, list(a.shape)] for n, a in arrays.items()]}
    head_bytes = json.dumps(head, separators=(",", ":"), ensure_ascii=False).encode("utf-8")
    payload = b"".join([_META_LENGTH.pack(len(head_bytes)), head_bytes, *(a.tobytes() for a in arrays.values())])
    return _HEAD.pack(MAGIC, len(payload), zlib.crc32(payload)) + payload


@dataclass(frozen=True)
class Record:
    offset: int                        # where it starts in the journal
    size: int                          # its bytes on disk, framing included
    kind: str
    meta: dict[str, Any]
    arrays: dict[str, np.ndarray]


def _decode_payload(offset: int, payload: bytes) -> Record:
    """The record in `payload` (whose checksum passed); ValueError if it is not one of ours."""
    (head_length,) = _META_LENGTH.unpack_from(payload)
    head = json.loads(payload[_META_LENGTH.size:_META_LENGTH.size + head_length].decode("utf-8"))
    if not isinstance(head, dict) or not isinstance(head.get("kind"), str) or not isinstance(head.get("meta"), dict):
        raise ValueError("not a record head")
    position, arrays = _META_LENGTH.size + head_length, {}
    for name, dtype_text, shape in head.get("arrays", []):
        dtype = np.dtype(dtype_text)
        if dtype.kind not in _DTYPE_KINDS or len(shape) > 4 or not all(isinstance(s, int) and s >= 0 for s in shape):
            raise ValueError(f"array {name}: unexpected type")
        count = math.prod(shape)
        size = dtype.itemsize * count
        if position + size > len(payload):
            raise ValueError(f"array {name} runs past the record")
        arrays[str(name)] = np.frombuffer(payload, dtype, count, position).reshape(shape).copy()
        position += size
    if position != len(payload):
        raise ValueError("bytes left over after the arrays")
    return Record(offset, _HEAD.size + len(payload), head["kind"], head["meta"], arrays)


#: The largest record a journal may hold (a pose of 64 DUTs × 100 000 samples is 77 MB): a length field
#: claiming more is damage, never a reason to read gigabytes.
MAX_RECORD_BYTES = 256 << 20
#: How much of the journal is searched at a time for the next record after damage.
_SEARCH_CHUNK_BYTES = 1 << 20
#: How far past the last record `Scan.tail_bytes` looks for what a killed write left.
_TAIL_LOOK_BYTES = 16 << 20


class _Bytes:
    """Random access to a journal's bytes: an open file (read as needed) or bytes in memory."""

    def __init__(self, data: bytes | None = None, fd: int | None = None) -> None:
        self._data, self._fd = data, fd
        self.size = len(data) if data is not None else os.fstat(fd).st_size  # type: ignore[arg-type]
        #: Bytes that may still be summed looking for records: twice the journal, so that searching a
        #: damaged journal cannot cost more than reading a sound one a few times.
        self.budget = 2 * self.size + MAX_RECORD_BYTES

    def read(self, offset: int, length: int) -> bytes:
        length = max(0, min(length, self.size - offset))
        if self._data is not None:
            return self._data[offset:offset + length]
        return os.pread(self._fd, length, offset)  # type: ignore[arg-type]

    def find(self, start: int) -> int:
        """The next offset of MAGIC at or after `start`, or -1."""
        while start < self.size:
            chunk = self.read(start, _SEARCH_CHUNK_BYTES + len(MAGIC) - 1)
            found = chunk.find(MAGIC)
            if found != -1:
                return start + found
            start += _SEARCH_CHUNK_BYTES
        return -1


#: How every record's JSON head begins (after its length): checked before a payload is read and summed.
_HEAD_START = b'{"kind":'


def _record_at(source: _Bytes, offset: int) -> Record | None:
    """The whole, checksummed record starting at `offset`, or None."""
    head = source.read(offset, _HEAD.size + _META_LENGTH.size + len(_HEAD_START))
    if len(head) < len(_HEAD_START) + _HEAD.size + _META_LENGTH.size:
        return None
    magic, length, crc = _HEAD.unpack_from(head)
    (head_length,) = _META_LENGTH.unpack_from(head, _HEAD.size)
    if magic != MAGIC or length > MAX_RECORD_BYTES or offset + _HEAD.size + length > source.size or \
            not len(_HEAD_START) <= head_length <= length - _META_LENGTH.size or \
            head[_HEAD.size + _META_LENGTH.size:] != _HEAD_START:
        return None
    source.budget -= length
    if source.budget < 0:
        return None  # searching damage has cost more than reading the journal twice over: the rest is lost
    payload = source.read(offset + _HEAD.size, length)
    if zlib.crc32(payload) != crc:
        return None
    try:
        return _decode_payload(offset, payload)
    except (ValueError, TypeError, UnicodeDecodeError, struct.error, OverflowError, MemoryError, RecursionError):
        return None


def _next_record(source: _Bytes, start: int) -> Record | None:
    """The first whole record at or after `start` (where reading picks up again after damage)."""
    position = source.find(start)
    while position != -1:
        record = _record_at(source, position)
        if record is not None:
            return record
        position = source.find(position + 1)
    return None


@dataclass
class Scan:
    """What a journal holds: its whole records in order, and what was wrong with the rest."""

    records: list[Record] = field(default_factory=list)
    end: int = 0                                         # just after the last whole record
    damaged: list[tuple[int, int]] = field(default_factory=list)  # (offset, bytes) skipped between records
    tail_bytes: int = 0                                  # non-zero bytes soon after `end`: a record written in part
    searched_out: bool = False                           # the search after damage ran out of budget

    @property
    def clean(self) -> bool:
        return not self.damaged and not self.tail_bytes


def _scan(source: _Bytes) -> Scan:
    result = Scan()
    position = 0
    while position < source.size:
        record = _record_at(source, position)
        if record is None:
            following = _next_record(source, position + 1)
            if following is None:
                break
            result.damaged.append((position, following.offset - position))
            record = following
        result.records.append(record)
        position = result.end = record.offset + record.size
    result.tail_bytes = len(source.read(result.end, _TAIL_LOOK_BYTES).rstrip(b"\0"))
    result.searched_out = source.budget < 0
    return result


def _tail_length(fd: int, found: Scan) -> int:
    """How much after the last whole record to keep when it is cut off: what a record header there claims
    (a damaged last record may end in zeros), else up to its last non-zero byte, never past the file."""
    size = os.fstat(fd).st_size - found.end
    head = os.pread(fd, _HEAD.size, found.end)
    claimed = 0
    if len(head) == _HEAD.size and head[:4] == MAGIC:
        claimed = _HEAD.size + min(_HEAD.unpack(head)[1], MAX_RECORD_BYTES)
    return min(size, max(claimed, found.tail_bytes))


def scan(data: bytes) -> Scan:
    """Every whole record in `data` (a journal's bytes)."""
    return _scan(_Bytes(data=data))


def read_journal(path: Path) -> Scan:
    """Every whole record of the journal at `path`, read record by record (memory bounded by its records,
    whatever the file's size); OSError if it cannot be read."""
    fd = os.open(path, os.O_RDONLY)
    try:
        return _scan(_Bytes(fd=fd))
    finally:
        os.close(fd)


class JournalWriter:
    """Appends records to one journal, each fsync'd before `append` returns.

    Space is allocated ahead of the records in chunks; `reserve_bytes` of it are kept back. When the
    disk is full and no more can be allocated, records still go into the reserve and
    `space_exhausted` turns true: the campaign stops, and the records that say so still fit.
    """

    def __init__(self, path: Path, fd: int, end: int, reserve_bytes: int) -> None:
        self.path = path
        self._fd = fd
        self.end = end
        self.reserve_bytes = reserve_bytes
        self.allocated = os.fstat(fd).st_size
        self.space_exhausted = False
        #: Where `reopen` kept what it cut off after the last whole record (None: nothing but zeros).
        self.tail_kept: Path | None = None

    @classmethod
    def create(cls, path: Path, first_record: bytes, reserve_bytes: int,
               before_replace: Callable[[], None] | None = None) -> JournalWriter:
        """A new journal holding `first_record`, in place of any journal at `path` (replaced whole, by
        rename, once the new one is on disk: a kill meanwhile leaves the old one or none). `before_replace`
        runs once the new one is on disk, just before it replaces the old (nothing has changed before)."""
        temporary = temporary_beside(path)
        with disk_errors(path, "the campaign journal"):
            fd = os.open(temporary, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o666)
            try:
                write_all(fd, first_record, 0)
                _allocate(fd, len(first_record), reserve_bytes + ALLOCATION_CHUNK_BYTES)
                os.fsync(fd)
                if before_replace is not None:
                    before_replace()
                os.replace(temporary, path)
            except BaseException:
                os.close(fd)
                temporary.unlink(missing_ok=True)
                raise
            fsync_directory(path.parent)
        return cls(path, fd, len(first_record), reserve_bytes)

    @classmethod
    def reopen(cls, path: Path, reserve_bytes: int) -> tuple[JournalWriter, Scan]:
        """Open an existing journal to append to it, and the scan of what is there. What follows the last
        whole record is cut off — a record a killed process left half-written, or a last record that was
        damaged — and kept beside the journal (`….journal.tail-<time>`, in `tail_kept`) unless it is only
        the zeros allocated ahead."""
        tail_kept = None
        with disk_errors(path, "the campaign journal"):
            fd = os.open(path, os.O_RDWR)
            try:
                found = _scan(_Bytes(fd=fd))
                if found.searched_out:
                    raise ConfigError(f"{path}: damaged beyond what reading may search through (a record in it "
                                      "could not be found); nothing was changed")
                if found.tail_bytes:
                    tail_kept = unused_name(path, "tail")
                    write_atomically(tail_kept, os.pread(fd, _tail_length(fd, found), found.end),
                                     "the end of the journal cut off")
                if os.fstat(fd).st_size > found.end:
                    os.ftruncate(fd, found.end)
                    os.fsync(fd)
            except BaseException:
                os.close(fd)
                raise
        writer = cls(path, fd, found.end, reserve_bytes)
        writer.tail_kept = tail_kept
        try:
            writer._ensure_room(0)
        except (DiskFull, ConfigError):
            writer.space_exhausted = True
        return writer, found

    def _ensure_room(self, length: int) -> None:
        """Allocate so that `length` more bytes and the reserve fit; DiskFull if the disk has no room."""
        needed = self.end + length + self.reserve_bytes
        if needed <= self.allocated:
            return
        try:
            _allocate(self._fd, self.allocated, needed + ALLOCATION_CHUNK_BYTES - self.allocated)
        except OSError as exc:
            self.allocated = os.fstat(self._fd).st_size
            if is_disk_full(exc):
                raise DiskFull(f"no space left on {self.path.parent.resolve()} (the campaign journal "
                               f"{self.path.name} could not grow)") from None
            raise ConfigError(f"{self.path}: the campaign journal could not grow: {exc.strerror or exc}") from None
        self.allocated = os.fstat(self._fd).st_size

    def append(self, record: bytes) -> None:
        """Write `record` after the last one and fsync; DiskFull when not even the reserve holds it."""
        try:
            self._ensure_room(len(record))
        except (DiskFull, ConfigError):  # full, over a quota or a size limit, failing: the reserve is for this
            self.space_exhausted = True
            if self.end + len(record) > self.allocated:
                raise
        with disk_errors(self.path, "the campaign journal"):
            write_all(self._fd, record, self.end)
            _sync(self._fd)
        self.end += len(record)

    def close(self) -> None:
        """Give back the space allocated ahead (zeros after the last record), then close."""
        if self._fd >= 0:
            try:
                os.ftruncate(self._fd, self.end)
            except OSError:
                pass  # the zeros stay: readers take them for the end
            os.close(self._fd)
            self._fd = -1


def _allocate(fd: int, offset: int, length: int) -> None:
    """Reserve disk blocks up to `offset + length` (zeros past the end of the file), where the file system
    can; where it cannot, write the zeros — past the file's end only, never over a record."""
    try:
        os.posix_fallocate(fd, offset, length)
    except OSError as exc:
        if is_disk_full(exc):
            raise
        end = os.fstat(fd).st_size
        if offset + length > end:
            write_all(fd, bytes(offset + length - end), end)
