"""Damaged campaigns: what a full disk, a kill, a bad sector, a careless copy or a hostile user could leave
beside `rig`. Each case starts from one small finished campaign (its journal, campaign file and
calibration) and damages it in one way; case `number` is reproducible.

Damage to the campaign file alone (its journal gone): cut short, bits flipped, a block zeroed, emptied,
random bytes, another HDF5 file, a dataset removed, reshaped or retyped, an attribute removed or of the
wrong type, a newer format, a pose-aligned dataset emptied or a row longer, a pose stored twice, rows
of zeros or NaN. Damage to the journal (the campaign file kept or not): cut short, bits flipped, zeroed,
random, emptied, its header destroyed, a pose record repeated, another campaign's journal, foreign
records. And files that are not files: a folder, a pipe.
"""

from __future__ import annotations

import os
import random
import shutil
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np

from accelcal_rig.store.journal import encode_record, read_journal

CAMPAIGN = "c.h5"
JOURNAL = "c.h5.journal"
CALIBRATION = "c.calibration.yaml"

SOURCE_PROCEDURE = """\
name: fuzz-source
rig: sim.yaml
setpoints_c: [25]
soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}
schedule: {kind: sphere, count: 14}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
"""


def make_source(folder: Path, rig_config: Path) -> Path:
    """A finished dry-run campaign in `folder` (and a second one, `other/`, for swapped journals)."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare

    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(rig_config, folder / "sim.yaml")
    procedure = folder / "source.yaml"
    procedure.write_text(SOURCE_PROCEDURE)
    for name, seed in ((CAMPAIGN, 5), (f"other/{CAMPAIGN}", 6)):
        (folder / name).parent.mkdir(exist_ok=True)
        run_campaign(prepare(procedure), folder / name, dry_run=True, seed=seed, overwrite=False,
                     calibration=(folder / name).with_name(CALIBRATION))
    return folder


def _flip_bits(path: Path, rng: random.Random, count: int, start: int = 0) -> str:
    data = bytearray(path.read_bytes())
    for _ in range(count):
        position = rng.randrange(start, len(data))
        data[position] ^= 1 << rng.randrange(8)
    path.write_bytes(bytes(data))
    return f"{count} bits flipped in {path.name}"


def _cut(path: Path, rng: random.Random) -> str:
    size = path.stat().st_size
    keep = rng.randrange(size)
    with path.open("r+b") as f:
        f.truncate(keep)
    return f"{path.name} cut to {keep} of {size} bytes"


def _zero_block(path: Path, rng: random.Random) -> str:
    data = bytearray(path.read_bytes())
    start, length = rng.randrange(len(data)), rng.choice([16, 512, 4096, 65536])
    data[start:start + length] = bytes(len(data[start:start + length]))
    path.write_bytes(bytes(data))
    return f"{length} bytes of {path.name} zeroed at {start}"


def _random_bytes(path: Path, rng: random.Random) -> str:
    path.write_bytes(bytes(rng.randrange(256) for _ in range(rng.choice([1, 100, 5000]))))
    return f"{path.name} replaced by random bytes"


def _h5_edit(path: Path, rng: random.Random) -> str:
    """One structural change made with h5py, as a script or a half-finished tool might."""
    with h5py.File(path, "r+") as f:
        datasets: list[str] = []
        f.visititems(lambda name, node: datasets.append(name) if isinstance(node, h5py.Dataset) else None)
        pose_aligned = [n for n in datasets if n.startswith(("poses/", "duts/", "simulation_truth/"))
                        and not n.endswith("polynomial_coefficients")]
        how = rng.choice(["delete", "reshape", "retype", "attr-delete", "attr-type", "version", "empty", "longer",
                          "duplicate", "zeros", "nan", "samples", "group"])
        if how == "delete":
            name = rng.choice(datasets)
            del f[name]
            return f"dataset {name} deleted"
        if how in ("reshape", "retype", "empty", "longer", "duplicate", "zeros", "nan"):
            name = rng.choice(pose_aligned)
            data = f[name][()]
            attrs = dict(f[name].attrs)
            if how == "reshape":
                data = np.zeros((3, 7, 5))
            elif how == "retype":
                data = np.array([b"not a number"] * max(1, len(data)))
            elif how == "empty":
                data = data[:0]
            elif how == "longer":
                data = np.concatenate([data, data[-1:]])
            elif how == "duplicate":
                data = np.concatenate([data[:1], data[:-1]])
            elif how == "zeros":
                data = np.zeros_like(data)
            elif data.dtype.kind == "f":
                data = data.copy()
                data[rng.randrange(len(data))] = np.nan
            del f[name]
            f.create_dataset(name, data=data)
            f[name].attrs.update(attrs)
            return f"dataset {name}: {how}"
        if how == "attr-delete":
            name = rng.choice(["state", "samples_per_pose", "format", "format_version", "procedure_path"])
            del f.attrs[name]
            return f"root attribute {name} deleted"
        if how == "attr-type":
            name = rng.choice(["state", "samples_per_pose", "runs", "dry_run", "seed"])
            f.attrs[name] = rng.choice(["abc", -5, 10**12, 1.5, np.array([1, 2, 3])])
            return f"root attribute {name} of another type"
        if how == "version":
            f.attrs["format_version"] = 99
            return "format version 99"
        if how == "samples":
            f.attrs["samples_per_pose"] = 10**6
            return "samples_per_pose claims 10^6"
        name = rng.choice(["soaks", "events", "plan", "duts", "config", "instruments"])
        del f[name]
        f.create_dataset(name, data=np.arange(3))
        return f"group {name} replaced by a dataset"


def _journal_edit(path: Path, rng: random.Random, other: Path) -> str:
    found = read_journal(path)
    data = path.read_bytes()
    how = rng.choice(["header", "repeat", "other", "foreign", "garbage", "middle"])
    if how == "header":
        first = found.records[0]
        _flip_bits(path, rng, 1, start=first.offset + 12)
        head = bytearray(path.read_bytes())
        return "the header record damaged" if head != data else "the header record damaged (no change)"
    poses = [r for r in found.records if r.kind == "pose"]
    if how == "repeat":
        record = rng.choice(poses)
        path.write_bytes(data + data[record.offset:record.offset + record.size])
        return f"pose record {record.meta['step_key']} appended a second time"
    if how == "other":
        shutil.copy(other, path)
        return "another campaign's journal"
    if how == "foreign":
        records = [encode_record("pose", {"step_key": "T25/pose01", "pose_number": 1, "serials": ["X"]}),
                   encode_record("state", {"state": 12}), encode_record("mystery", {}), encode_record("header", {})]
        path.write_bytes(data + b"".join(rng.sample(records, 2)))
        return "records of the wrong shape appended"
    if how == "garbage":
        path.write_bytes(data + bytes(rng.randrange(256) for _ in range(rng.choice([3, 300, 30000]))))
        return "garbage appended"
    record = rng.choice(poses)
    _flip_bits(path, rng, rng.choice([1, 3]), start=record.offset)
    return f"bits flipped from pose record {record.meta['step_key']} on"


#: Damage kinds: (name, where, function of (case folder, rng, source folder) → description).
Damage = Callable[[Path, random.Random, Path], str]


def _only_file(damage: Callable[[Path, random.Random], str]) -> Damage:
    def apply(folder: Path, rng: random.Random, source: Path) -> str:
        (folder / JOURNAL).unlink()
        return "no journal; " + damage(folder / CAMPAIGN, rng)
    return apply


def _journal(damage: Callable[[Path, random.Random], str], keep_file: bool) -> Damage:
    def apply(folder: Path, rng: random.Random, source: Path) -> str:
        if not keep_file:
            (folder / CAMPAIGN).unlink()
        return ("" if keep_file else "no campaign file; ") + damage(folder / JOURNAL, rng)
    return apply


def _not_a_file(kind: str) -> Damage:
    def apply(folder: Path, rng: random.Random, source: Path) -> str:
        target = folder / (CAMPAIGN if kind != "journal-folder" else JOURNAL)
        target.unlink()
        if kind == "fifo":
            (folder / JOURNAL).unlink()
            os.mkfifo(target)
        else:
            target.mkdir()
        return {"folder": "the campaign file is a folder", "fifo": "the campaign file is a pipe (no journal)",
                "journal-folder": "the journal is a folder"}[kind]
    return apply


def _foreign_hdf5(path: Path, rng: random.Random) -> str:
    path.unlink()
    with h5py.File(path, "w") as f:
        f.create_dataset("images", data=np.zeros((4, 4)))
        f.attrs["format"] = rng.choice(["something else", "accelcal-rig campaign"])
    return "another HDF5 file"


def _both(folder: Path, rng: random.Random, source: Path) -> str:
    return _flip_bits(folder / CAMPAIGN, rng, 20) + "; " + _cut(folder / JOURNAL, rng)


DAMAGES: list[tuple[str, Damage]] = [
    ("file cut", _only_file(_cut)), ("file bits", _only_file(lambda p, r: _flip_bits(p, r, r.choice([1, 5, 50])))),
    ("file zeroed", _only_file(_zero_block)), ("file empty", _only_file(lambda p, r: (p.write_bytes(b""), "emptied")[1])),
    ("file random", _only_file(_random_bytes)), ("file foreign", _only_file(_foreign_hdf5)),
    ("file edit", _only_file(_h5_edit)), ("file edit", _only_file(_h5_edit)), ("file edit", _only_file(_h5_edit)),
    ("journal cut", _journal(_cut, keep_file=False)), ("journal cut, file kept", _journal(_cut, keep_file=True)),
    ("journal bits", _journal(lambda p, r: _flip_bits(p, r, r.choice([1, 4, 40])), keep_file=False)),
    ("journal bits, file kept", _journal(lambda p, r: _flip_bits(p, r, r.choice([1, 4, 40])), keep_file=True)),
    ("journal zeroed", _journal(_zero_block, keep_file=False)), ("journal random", _journal(_random_bytes, keep_file=True)),
    ("journal empty", _journal(lambda p, r: (p.write_bytes(b""), "emptied")[1], keep_file=True)),
    ("journal edit", lambda f, r, s: _journal_edit(f / JOURNAL, r, s / "other" / JOURNAL)),
    ("journal edit", lambda f, r, s: _journal_edit(f / JOURNAL, r, s / "other" / JOURNAL)),
    ("both", _both), ("folder", _not_a_file("folder")), ("fifo", _not_a_file("fifo")),
    ("journal folder", _not_a_file("journal-folder")),
]


def damaged_case(number: int, source: Path, folder: Path) -> str:
    """Case `number` in `folder` (a copy of the source campaign, damaged); returns what was done."""
    rng = random.Random(number)
    folder.mkdir(parents=True, exist_ok=True)
    for name in (CAMPAIGN, JOURNAL, CALIBRATION, "sim.yaml", "source.yaml"):
        shutil.copy(source / name, folder / name)
    name, damage = DAMAGES[number % len(DAMAGES)]
    return f"{name}: {damage(folder, rng, source)}"
