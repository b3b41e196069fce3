"""The journal: records come back bit for bit, and no damage to its bytes costs more than what it hit."""

from __future__ import annotations

import errno
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.errors import DiskFull
from accelcal_rig.store import journal
from accelcal_rig.store.journal import JournalWriter, encode_record, read_journal, scan


def records(n: int) -> list[bytes]:
    rng = np.random.default_rng(7)
    return [encode_record("pose", {"step_key": f"T20/pose{k:02d}", "note": "ünïcode"},
                          {"codes": rng.integers(-2**19, 2**19, (20, 3), dtype="i4"), "mean": rng.normal(size=3),
                           "flag": np.array([True, False])}) for k in range(n)]


def test_records_come_back_bit_for_bit() -> None:
    encoded = records(3)
    found = scan(b"".join(encoded))
    assert found.clean and [r.meta["step_key"] for r in found.records] == ["T20/pose00", "T20/pose01", "T20/pose02"]
    assert found.end == sum(map(len, encoded))
    again = encode_record(found.records[1].kind, found.records[1].meta, found.records[1].arrays)
    assert again == encoded[1]
    assert found.records[0].arrays["codes"].dtype == np.int32 and found.records[0].meta["note"] == "ünïcode"


def test_a_record_cut_anywhere_is_a_tail_and_the_ones_before_are_whole() -> None:
    encoded = records(3)
    whole = b"".join(encoded[:2])
    for cut in range(1, len(encoded[2])):
        found = scan(whole + encoded[2][:cut])
        assert len(found.records) == 2 and found.end == len(whole) and not found.damaged, cut
        assert found.tail_bytes > 0 or not encoded[2][:cut].strip(b"\0")


def test_preallocated_zeros_are_the_end_not_damage() -> None:
    found = scan(b"".join(records(2)) + bytes(4096))
    assert found.clean and len(found.records) == 2


@pytest.mark.parametrize("where", ["head", "payload", "zeroed"])
def test_damage_in_the_middle_loses_that_record_only(where: str) -> None:
    encoded = records(4)
    data = bytearray(b"".join(encoded))
    start = len(encoded[0])
    if where == "head":
        data[start + 5] ^= 0x40          # the length field
    elif where == "payload":
        data[start + 200] ^= 0x01        # one bit of the codes
    else:
        data[start:start + len(encoded[1])] = bytes(len(encoded[1]))
    found = scan(bytes(data))
    assert [r.meta["step_key"] for r in found.records] == ["T20/pose00", "T20/pose02", "T20/pose03"]
    assert found.damaged == [(start, len(encoded[1]))]


def test_a_foreign_file_holds_no_records() -> None:
    found = scan(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 8)
    assert found.records == [] and found.end == 0 and found.tail_bytes > 0


def test_the_writer_appends_reopens_and_cuts_a_half_written_record(tmp_path: Path) -> None:
    path = tmp_path / "c.journal"
    encoded = records(4)
    writer = JournalWriter.create(path, encoded[0], reserve_bytes=4096)
    writer.append(encoded[1])
    assert writer.allocated >= writer.end + 4096  # space kept ahead of the records
    writer.close()
    assert path.stat().st_size == len(encoded[0]) + len(encoded[1])  # given back on close
    with path.open("ab") as f:
        f.write(encoded[2][:100])                 # what a kill in the middle of a write leaves
    writer, found = JournalWriter.reopen(path, reserve_bytes=4096)
    assert len(found.records) == 2 and found.tail_bytes == 100
    writer.append(encoded[3])
    writer.close()
    assert [r.meta["step_key"] for r in read_journal(path).records] == ["T20/pose00", "T20/pose01", "T20/pose03"]


def test_create_replaces_a_journal_whole(tmp_path: Path) -> None:
    path = tmp_path / "c.journal"
    path.write_bytes(b"old campaign")
    JournalWriter.create(path, records(1)[0], reserve_bytes=0).close()
    assert len(read_journal(path).records) == 1 and sorted(p.name for p in tmp_path.iterdir()) == ["c.journal"]


def test_a_full_disk_leaves_the_reserve_for_the_records_that_stop_the_campaign(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "c.journal"
    encoded = records(2)
    monkeypatch.setattr(journal, "ALLOCATION_CHUNK_BYTES", 0)  # allocate no more than the reserve ahead
    writer = JournalWriter.create(path, encoded[0], reserve_bytes=len(encoded[1]) + 10)
    assert writer.allocated == writer.end + len(encoded[1]) + 10

    def full(fd: int, offset: int, length: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(journal, "_allocate", full)
    writer.append(encoded[1])                     # no room to grow: it goes into the reserve
    assert writer.space_exhausted
    with pytest.raises(DiskFull, match="no space left on .*could not grow"):
        writer.append(encoded[1])                 # the reserve is used up: refused, nothing written
    writer.close()
    assert len(read_journal(path).records) == 2


def test_without_fallocate_the_zeros_go_past_the_records_only(tmp_path: Path, monkeypatch) -> None:
    """A file system without posix_fallocate: the space ahead is written as zeros after the records."""
    def unsupported(fd: int, offset: int, length: int) -> None:
        raise OSError(errno.EOPNOTSUPP, "Operation not supported")

    monkeypatch.setattr(journal.os, "posix_fallocate", unsupported)
    path = tmp_path / "c.journal"
    encoded = records(3)
    writer = JournalWriter.create(path, encoded[0], reserve_bytes=4096)
    writer.append(encoded[1])
    writer.append(encoded[2])
    assert writer.allocated >= writer.end + 4096
    writer.close()
    found = read_journal(path)
    assert found.clean and [r.meta["step_key"] for r in found.records] == ["T20/pose00", "T20/pose01", "T20/pose02"]


def test_what_follows_the_last_whole_record_is_kept_when_cut_off(tmp_path: Path) -> None:
    path = tmp_path / "c.journal"
    encoded = records(3)
    damaged = bytearray(encoded[2])
    damaged[40] ^= 0x01  # a whole last record with one bit flipped: not a kill's half record, still not readable
    path.write_bytes(encoded[0] + encoded[1] + bytes(damaged))
    writer, found = JournalWriter.reopen(path, reserve_bytes=0)
    writer.close()
    assert len(found.records) == 2 and writer.tail_kept is not None
    assert writer.tail_kept.read_bytes() == bytes(damaged) and path.read_bytes() == encoded[0] + encoded[1]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.journal", writer.tail_kept.name]
