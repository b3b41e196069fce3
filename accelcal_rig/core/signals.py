"""Keep writes whole: a stop requested by a signal waits until the write in progress is done.

Python runs signal handlers between bytecodes, so a handler that raises at once could land between two
datasets of one pose. The CLI's handler calls `stop_when_safe` instead: outside a critical section it
raises at once; inside one it records the stop, which is raised as the outermost section ends.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


class TerminationRequested(BaseException):
    """SIGTERM arrived: stop like Ctrl-C, through the safe state."""


_depth = 0
_pending: BaseException | None = None


@contextmanager
def signals_deferred() -> Iterator[None]:
    """A critical section: a stop requested inside it is raised only when it ends (sections nest)."""
    global _depth, _pending
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0 and _pending is not None:
            stop, _pending = _pending, None
            raise stop


def stop_when_safe(stop: BaseException) -> None:
    """Raise `stop` now, or when the current critical section ends if one is running."""
    global _pending
    if _depth > 0:
        _pending = stop
        return
    raise stop
