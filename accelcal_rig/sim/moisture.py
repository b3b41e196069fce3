"""The chamber air's moisture, enough to test frost and condensation handling.

The air's dew point relaxes (time constant `moisture_time_constant_min`) toward a target: the dry-air
purge's dew point while the purge is on; otherwise the room's dew point, capped by the air temperature
(cold air cannot hold more: the evaporator freezes the rest out as frost, which comes back as the chamber
warms). Shorter than the fixture's time constant by default, so on warming from the cold the air's dew
point rises faster than the DUTs warm: what condenses on a real cold fixture.
"""

from __future__ import annotations

import math
from collections.abc import Callable


class ChamberMoisture:
    def __init__(self, room_dew_point_c: float, purge_dew_point_c: float, time_constant_s: float,
                 air_c: Callable[[float], float], t0_s: float = 0.0) -> None:
        self._room_dew_point_c = room_dew_point_c
        self._purge_dew_point_c = purge_dew_point_c
        self._tau_s = time_constant_s
        self._air_c = air_c
        self.purge_on = False
        self._t_s = t0_s
        self._dew_point_c = min(room_dew_point_c, air_c(t0_s))

    def set_purge(self, t_s: float, on: bool) -> None:
        self._advance(t_s)
        self.purge_on = on

    def dew_point_c(self, t_s: float) -> float:
        self._advance(t_s)
        return self._dew_point_c

    def _advance(self, t_s: float) -> None:
        """Step the relaxation to `t_s` in steps short against the time constant. The air temperature is the
        thermal model's, which only moves forward: over a gap between requests it is the latest one (the
        line simulator advances the moisture on every request, a few seconds apart)."""
        step_s = self._tau_s / 10.0
        while self._t_s < t_s:
            dt = min(step_s, t_s - self._t_s)
            self._t_s += dt
            air = self._air_c(self._t_s)
            target = self._purge_dew_point_c if self.purge_on else min(self._room_dew_point_c, air)
            self._dew_point_c += (target - self._dew_point_c) * (1.0 - math.exp(-dt / self._tau_s))
            self._dew_point_c = min(self._dew_point_c, air)
