"""Durable writes: every file the program writes for a campaign (and its results) goes through here.

Files other than the journal are never changed in place: a new version is written beside the old one,
fsync'd, renamed over it and the folder fsync'd, so a reader (or a crash) sees the old file or the new,
never a mixture. A full disk is one error type naming the folder, whatever wrote.
"""

from __future__ import annotations

import datetime as dt
import errno
import itertools
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from accelcal_rig.errors import ConfigError, DiskFull

#: errno values that mean "the disk (or the user's quota) is full".
_FULL = frozenset({errno.ENOSPC, errno.EDQUOT})


def is_disk_full(exc: BaseException) -> bool:
    return isinstance(exc, OSError) and exc.errno in _FULL


def temporary_beside(path: Path) -> Path:
    """Where a new version of `path` is built before it replaces `path` (same folder: rename is atomic)."""
    return path.with_name(f"{path.name}.tmp-{os.getpid()}")


def unused_name(path: Path, why: str) -> Path:
    """`<path>.<why>-20261201T081500` (with `-2`, `-3`, … if taken): where a copy set aside is kept."""
    stamp = dt.datetime.now(dt.UTC).strftime("%Y%m%dT%H%M%S")
    for count in itertools.count(1):
        candidate = path.with_name(f"{path.name}.{why}-{stamp}{'' if count == 1 else f'-{count}'}")
        if not os.path.lexists(candidate):
            return candidate
    raise AssertionError("unreachable")


def stale_temporaries(path: Path) -> list[Path]:
    """Versions of `path`, and of copies set aside beside it, that a killed process left half-built."""
    return sorted(p for pattern in (f"{path.name}.tmp-*", f"{path.name}.tail-*.tmp-*")
                  for p in path.parent.glob(pattern))


def clear_stale_temporaries(*paths: Path) -> None:
    """Remove what killed processes left half-built beside `paths` (the caller holds the campaign)."""
    for path in paths:
        for stale in stale_temporaries(path):
            with disk_errors(stale, "a file left half-built"):
                stale.unlink(missing_ok=True)


def clear_dead_temporaries(*paths: Path) -> None:
    """Remove what processes that are gone left half-built beside `paths` — a file no lock guards (a
    calibration, a certificate, a progress view), whose writer may still be at work: only a `.tmp-PID` whose
    process has ended on this machine goes (a live or unknown one's stays)."""
    for path in paths:
        for stale in stale_temporaries(path):
            pid = stale.name.rpartition(".tmp-")[2]
            if pid.isdigit() and not _alive(int(pid)):
                with disk_errors(stale, "a file left half-built"):
                    stale.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def remove(path: Path, what: str) -> None:
    """Remove `path` if it is there; an error is one line naming it."""
    with disk_errors(path, what):
        path.unlink(missing_ok=True)


@contextmanager
def disk_errors(path: Path, what: str) -> Iterator[None]:
    """OSError while writing `path` → DiskFull (a full disk) or ConfigError (permission, no folder, …)."""
    try:
        yield
    except OSError as exc:
        if is_disk_full(exc):
            raise DiskFull(f"no space left on {path.parent.resolve()} (writing {what} {path.name})") from None
        raise ConfigError(f"{path}: cannot write {what}: {exc.strerror or exc}") from None


def write_all(fd: int, data: bytes | memoryview, offset: int) -> None:
    """pwrite until every byte is written (a write may be short)."""
    view = memoryview(data)
    while view:
        written = os.pwrite(fd, view, offset)
        view, offset = view[written:], offset + written


def fsync_directory(folder: Path) -> None:
    """Make a rename or a new file in `folder` survive a power cut."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_atomically(path: Path, data: bytes, what: str) -> None:
    """Replace `path` with `data`: built beside it, fsync'd, renamed over it. The new file gets the
    permissions the user's umask gives. On failure `path` is as it was and nothing else is left behind."""
    temporary = temporary_beside(path)
    with disk_errors(path, what):
        try:
            fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o666)
            try:
                write_all(fd, data, 0)
                os.fsync(fd)
            finally:
                os.close(fd)
            os.replace(temporary, path)
        except BaseException:
            temporary.unlink(missing_ok=True)
            raise
        fsync_directory(path.parent)


def write_text_atomically(path: Path, text: str, what: str) -> None:
    write_atomically(path, text.encode("utf-8"), what)


def read_regular_file(path: Path, limit: int, what: str) -> bytes:
    """The bytes of a regular file of at most `limit` bytes (a device, a pipe or a folder is refused
    without waiting on it, a larger file without reading it); ConfigError naming `path`."""
    try:
        info = os.stat(path)
        if stat.S_ISDIR(info.st_mode):
            raise ConfigError(f"{path}: is a folder, not a file")
        if not stat.S_ISREG(info.st_mode):
            raise ConfigError(f"{path}: not a regular file")
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{path}: cannot read: {str(exc).splitlines()[0]}") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced by something else meanwhile
            raise ConfigError(f"{path}: not a regular file")
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise ConfigError(f"{path}: more than {limit} bytes: {what} is at most {limit} bytes")
        return b"".join(chunks)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)


def free_bytes(folder: Path) -> int:
    """Space an unprivileged writer may still use in `folder`."""
    stats = os.statvfs(folder)
    return stats.f_bavail * stats.f_frsize
