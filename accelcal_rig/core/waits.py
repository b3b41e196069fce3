"""The one way to wait: poll a condition on the clock until it holds or its deadline passes."""

from __future__ import annotations

from collections.abc import Callable

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.errors import WaitTimeout

#: Turntable position polling interval, from the time a move could first have arrived (its travel at the
#: configured speeds).
MOVE_POLL_S = 0.5


def wait_until(clock: Clock, condition: Callable[[], bool], *, timeout_s: float, poll_s: float,
               what: str) -> float:
    """Return the clock time at which `condition()` first held; raise WaitTimeout naming `what` if never.

    The condition is evaluated once more at the deadline itself, so a wait never gives up early.
    """
    deadline = clock.now() + timeout_s
    while True:
        if condition():
            return clock.now()
        remaining = deadline - clock.now()
        if remaining <= 0:
            raise WaitTimeout(f"{what}: not reached within {format_duration(timeout_s)}")
        clock.sleep(min(poll_s, remaining))
