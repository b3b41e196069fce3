"""A simulated ACUTROL3000's working limits, per Command Profiler mode and axis (TM-8004-C §4.6.2, 4.6.8):
the rate limit and the acceleration limit each mode's motion is held to, written and read back as a
controller does.

- At power-up (not in the manual: the rig config stands in for the factory set-up) every mode's
  acceleration limit is the axis's `max_acceleration_dps2` (100 °/s² where it has none, as the simulated
  rate motion takes), the rate limit the axis's `max_rate_dps` in Rate mode and its travel speed in the
  others.
- The rate limit "has no significance for the Abort and Off (Zero Rate) Modes. In these modes the rate limit
  is forced to zero" (§4.6.8): it reads 0 there whatever is written.
- A rate limit is a magnitude and an acceleration limit of zero "should never be commanded because all
  changes to motion command states would be inhibited" (§4.6.2, 4.6.8): a negative rate limit or an
  acceleration limit not above zero is refused [inferred: the manual names only an invalid mode or axis as
  an error].
- What the simulated motion obeys: Rate mode's limits, for rate demands (sim/turntable_acl.py). A position
  move travels at the axis's configured speed whatever Position mode's limits read (sim/turntable_motion.py
  has no per-move speed); Synthesis and Track limits are held and read back only (no such modes).
"""

from __future__ import annotations

_ZERO_RATE_MODES = ("Abort", "Off")


class ModeLimits:
    """Rate and acceleration limits by (mode, 0-based axis); modes as acl_arguments.MODES names them."""

    def __init__(self, speeds_deg_s: list[float], max_rates_deg_s: list[float | None],
                 accelerations_deg_s2: list[float]) -> None:
        self._rate: dict[tuple[str, int], float] = {}
        self._acceleration: dict[tuple[str, int], float] = {}
        self._speeds = speeds_deg_s
        self._max_rates = max_rates_deg_s
        self._accelerations = accelerations_deg_s2

    def rate(self, mode: str, axis: int) -> float:
        if mode in _ZERO_RATE_MODES:
            return 0.0
        default = self._max_rates[axis] if mode == "Rate" else None
        return self._rate.get((mode, axis), default if default is not None else self._speeds[axis])

    def acceleration(self, mode: str, axis: int) -> float:
        return self._acceleration.get((mode, axis), self._accelerations[axis])

    def set_rate(self, mode: str, axis: int, value: float) -> None:
        if rate_limit_valid(value):
            self._rate[(mode, axis)] = value

    def set_acceleration(self, mode: str, axis: int, value: float) -> None:
        if acceleration_limit_valid(value):
            self._acceleration[(mode, axis)] = value


def rate_limit_valid(value: float) -> bool:
    """A rate limit a controller takes (a magnitude): refused before anything is carried out otherwise."""
    return value >= 0


def acceleration_limit_valid(value: float) -> bool:
    """An acceleration limit a controller takes: above zero (§4.6.2)."""
    return value > 0
