"""When a simulated part's samples are due: one every period of its output data rate, counted from when it began
converting (or changed its rate), on the lab's clock. A part's register model makes the newest due sample only
when the host looks at it: a sample nobody reads costs nothing. Shared by the register models that the host
polls (the ICM-42688-P's, the LIS3MDL's)."""

from __future__ import annotations

import math

#: A read exactly at a sample instant sees that sample (in samples: far above the clock's rounding).
_TICK_EPS = 1e-6


class SampleTicks:
    """The sample clock of one converting part."""

    def __init__(self) -> None:
        self._since: float | None = None
        self._last = 0

    @property
    def running(self) -> bool:
        return self._since is not None

    @property
    def since_s(self) -> float | None:
        """When the part began converting (or changed its rate); None while it does not."""
        return self._since

    def start(self, now_s: float) -> None:
        """Converting from `now_s`: the first sample one period later."""
        self._since, self._last = now_s, 0

    def stop(self) -> None:
        self._since, self._last = None, 0

    def restart(self, now_s: float) -> None:
        """A new rate while converting: counted afresh from `now_s`."""
        if self._since is not None:
            self.start(now_s)

    def newest(self, now_s: float, odr_hz: float) -> tuple[float, int] | None:
        """(the time of the newest sample due by `now_s`, how many samples came since the last one looked at)
        where one is new; None where none is (or the part is not converting)."""
        if self._since is None:
            return None
        tick = math.floor((now_s - self._since) * odr_hz + _TICK_EPS)
        if tick <= self._last:
            return None
        came, self._last = tick - self._last, tick
        return self._since + tick / odr_hz, came
