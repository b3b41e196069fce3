"""A controller's own clock and calendar, running on the shared clock: set from the date and time the
simulator starts (or as a client writes them), it moves only as the lab's time does, so a dry run's
virtual hours are the calendar's hours too."""

from __future__ import annotations

from datetime import datetime, timedelta

from accelcal_rig.core.clock import Clock


class ControllerCalendar:
    def __init__(self, clock: Clock, start: datetime | None = None) -> None:
        """`start`: the calendar now (default: this computer's local time, to the second)."""
        self._clock = clock
        now = (start or datetime.now()).replace(microsecond=0)
        self._origin = now - timedelta(seconds=clock.now())  # the calendar at the clock's zero

    def now(self) -> datetime:
        return self._origin + timedelta(seconds=self._clock.now())

    def set(self, when: datetime) -> None:
        """The controller's clock set to `when` (a client's date or time write), going on from there."""
        self._origin = when - timedelta(seconds=self._clock.now())
