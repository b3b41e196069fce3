"""Durable writes: every file the program writes for a campaign (and its results) goes through here.

Files other than the journal are never changed in place: a new version is written beside the old one,
fsync'd, renamed over it and the folder fsync'd, so a reader (or a crash) sees the old file or the new,
never a mixture. A full disk is one error type naming the folder, whatever wrote.
"""

from __future__ import annotations

import errno
import os
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


def stale_temporaries(path: Path) -> list[Path]:
    """Versions of `path` that a killed process left half-built."""
    return sorted(path.parent.glob(f"{path.name}.tmp-*"))


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


def free_bytes(folder: Path) -> int:
    """Space an unprivileged writer may still use in `folder`."""
    stats = os.statvfs(folder)
    return stats.f_bavail * stats.f_frsize
