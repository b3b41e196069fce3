"""One writer per campaign: `<campaign>.lock`, taken before any byte of the campaign changes.

The lock is an advisory `flock` on a small file beside the campaign, which also says who holds it
(process, host, command, since when). The kernel drops it when its process ends, however it ends, so a
`kill -9` never leaves a campaign locked. The file stays while a campaign is there; only a run that made it
and failed before its campaign started removes it again, while holding it — and a writer that gets the lock
checks that the file it locked is still the one at the path (else it locks the new one), so two writers
never hold two different files. Readers never take it, they only ask whether it is held.
"""

from __future__ import annotations

import datetime as dt
import errno
import fcntl
import json
import os
import socket
import stat
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from accelcal_rig.errors import ConfigError
from accelcal_rig.store.paths import lock_path

#: How long a writer keeps trying when the lock is busy (a reader asking whether it is held takes it,
#: shared, for a moment).
ACQUIRE_PATIENCE_S = 1.0
_RETRY_S = 0.02


class CampaignBusy(ConfigError):
    """Another process holds the campaign: nothing was changed."""


#: Locks this process holds: lock file → [descriptor, nesting depth].
_held: dict[Path, list[int]] = {}


def _key(campaign: Path) -> Path:
    return lock_path(campaign).resolve()


@contextmanager
def campaign_lock(campaign: Path, command: str) -> Iterator[None]:
    """Hold the campaign for the duration (reentrant within a process); CampaignBusy naming the holder
    when another process has it."""
    acquire(campaign, command)
    try:
        yield
    finally:
        release(campaign)


def acquire(campaign: Path, command: str) -> None:
    key = _key(campaign)
    if key in _held:
        _held[key][1] += 1
        return
    fd = _open_lock(campaign, key)
    deadline = time.monotonic() + ACQUIRE_PATIENCE_S
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN) or time.monotonic() > deadline:
                holder = _describe(fd)
                os.close(fd)
                raise CampaignBusy(f"{campaign}: in use by {holder}; nothing was changed") from None
            time.sleep(_RETRY_S)
            continue
        if _still_at(fd, key):
            break
        os.close(fd)  # its holder removed it while we waited: lock the file now at the path
        fd = _open_lock(campaign, key)
    info = {"pid": os.getpid(), "host": socket.gethostname(), "command": command,
            "since": dt.datetime.now(dt.UTC).isoformat(timespec="seconds")}
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(info).encode(), 0)
    except OSError as exc:  # a full disk, say: the lock is held all the same, only who holds it is unsaid
        if exc.errno not in (errno.ENOSPC, errno.EDQUOT):
            os.close(fd)
            raise ConfigError(f"{campaign}: cannot write its lock {key.name}: {exc.strerror}") from None
    _held[key] = [fd, 1]


def _open_lock(campaign: Path, key: Path) -> int:
    try:
        fd = os.open(key, os.O_RDWR | os.O_CREAT | os.O_NONBLOCK, 0o666)
    except OSError as exc:
        raise ConfigError(f"{campaign}: cannot take its lock {key.name}: {exc.strerror}") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise ConfigError(f"{campaign}: its lock {key.name} is not a regular file")
    return fd


def _still_at(fd: int, key: Path) -> bool:
    """Whether the locked file is the one at `key` (not one its last holder removed)."""
    try:
        at_path = os.stat(key)
    except FileNotFoundError:
        return False
    held = os.fstat(fd)
    return (held.st_dev, held.st_ino) == (at_path.st_dev, at_path.st_ino)


def remove_lock_file(campaign: Path) -> None:
    """Remove the lock file while holding it (only the outermost holder in this process may): for a run that
    made it and whose campaign never started. A writer waiting on it finds it gone and locks a new one."""
    entry = _held.get(_key(campaign))
    if entry is None or entry[1] != 1:
        return
    try:
        os.unlink(_key(campaign))
    except OSError:
        pass  # a lock file left behind is harmless: the next writer takes it


def release(campaign: Path) -> None:
    key = _key(campaign)
    entry = _held.get(key)
    if entry is None:
        return
    entry[1] -= 1
    if entry[1] == 0:
        del _held[key]
        try:
            os.ftruncate(entry[0], 0)  # nobody holds it now: say so
        except OSError:
            pass  # the kernel drops the lock with the descriptor all the same
        os.close(entry[0])             # closing drops the flock


def holds(campaign: Path) -> bool:
    """Whether this process holds the campaign."""
    return _key(campaign) in _held


def holder(campaign: Path) -> str | None:
    """Who holds the campaign (`pid 4242 on rig-pc (rig run since …)`), or None when nobody does.
    Never creates the lock file."""
    if holds(campaign):
        return f"this process (pid {os.getpid()})"
    try:
        fd = os.open(lock_path(campaign), os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError:
            return _describe(fd)
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    finally:
        os.close(fd)


def _describe(fd: int) -> str:
    try:
        info = json.loads(os.pread(fd, 4096, 0).decode("utf-8"))
        return f"pid {info['pid']} on {info['host']} ({info['command']} since {info['since']})"
    except (OSError, ValueError, KeyError, TypeError):
        return "another process (it has not said which yet)"
