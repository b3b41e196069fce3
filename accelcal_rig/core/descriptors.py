"""Writing to and reading from a non-blocking descriptor (a serial device, a pseudo-terminal's far end)
within a deadline: a system call each, where the device's own library loops in Python."""

from __future__ import annotations

import os
import select
import time


def write_within(fd: int, data: bytes, deadline_s: float) -> int:
    """Write all of `data` to `fd`, waiting for room until the monotonic `deadline_s`; the bytes left
    unwritten (0: all of it). OSError (the far end went away) is the caller's."""
    view = memoryview(data)
    while view:
        try:
            view = view[os.write(fd, view):]
            continue
        except BlockingIOError:  # the buffer is full: wait until it drains
            pass
        left_s = deadline_s - time.monotonic()
        if left_s <= 0 or not select.select([], [fd], [], left_s)[1]:
            break
    return len(view)


def read_within(fd: int, deadline_s: float) -> bytes | None:
    """What has arrived on `fd`, waiting for it until the monotonic `deadline_s` (None: nothing by then). b""
    is the end of the file. OSError is the caller's."""
    while True:
        left_s = deadline_s - time.monotonic()
        if not select.select([fd], [], [], max(0.0, left_s))[0]:
            return None
        try:
            return os.read(fd, 65536)
        except BlockingIOError:  # readiness without data: wait again, while there is time
            if left_s <= 0:
                return None
