"""Who opens and closes the client end of the simulators' pseudo-terminals: Linux's inotify, one instance for many
paths, through ctypes (the standard library has no binding for it). A simulated serial device keeps its client end
open itself (so the path works between clients), so it never sees a client go on its own end; this is what tells
it, as DTR tells a USB serial board. Where inotify is missing (not Linux), nothing is watched."""

from __future__ import annotations

import ctypes
import os
import struct
from typing import Any

_IN_CLOSE_WRITE = 0x08
_IN_CLOSE_NOWRITE = 0x10
_IN_OPEN = 0x20
_OPENS_AND_CLOSES = _IN_OPEN | _IN_CLOSE_WRITE | _IN_CLOSE_NOWRITE
#: struct inotify_event without its name (wd, mask, cookie, len), then `len` bytes of name.
_EVENT = struct.Struct("iIII")


def _libc() -> Any | None:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.inotify_init1, libc.inotify_add_watch, libc.inotify_rm_watch  # noqa: B018 - present, or not Linux
    except (OSError, AttributeError):
        return None
    return libc


class ClientWatch:
    """The opens and closes of watched paths by any process. `fileno` is readable when some have happened."""

    def __init__(self) -> None:
        self._libc = _libc()
        self.fileno = self._libc.inotify_init1(os.O_NONBLOCK | os.O_CLOEXEC) if self._libc is not None else -1

    def watch(self, path: str) -> int | None:
        """Start watching `path`; the watch's number, None if it cannot be watched."""
        if self.fileno < 0:
            return None
        number = self._libc.inotify_add_watch(self.fileno, os.fsencode(path), _OPENS_AND_CLOSES)  # type: ignore[union-attr]
        return number if number >= 0 else None

    def forget(self, number: int) -> None:
        if self.fileno >= 0:
            self._libc.inotify_rm_watch(self.fileno, number)  # type: ignore[union-attr]

    def changed(self) -> set[int]:
        """The watches whose path was opened or closed since the last call."""
        seen: set[int] = set()
        while self.fileno >= 0:
            try:
                events = os.read(self.fileno, 4096)
            except BlockingIOError:
                break
            offset = 0
            while offset < len(events):
                number, mask, _, name_length = _EVENT.unpack_from(events, offset)
                if mask & _OPENS_AND_CLOSES:
                    seen.add(number)
                offset += _EVENT.size + name_length
        return seen

    def close(self) -> None:
        if self.fileno >= 0:
            os.close(self.fileno)
            self.fileno = -1
