"""Write-safety gates in front of any driver: nothing outside the rig's limits reaches the wire."""

from __future__ import annotations

import math

import numpy as np

from accelcal_rig.config.rig import ChamberConfig, TurntableConfig
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import controller_limits, setpoint_decimals
from accelcal_rig.instruments.interfaces import Chamber, Turntable

#: A setpoint read back further than this from what was written means the controller did not take it.
SETPOINT_READBACK_TOLERANCE_C = 0.05
#: Readings outside this are not a chamber's air: the map, word order, profile or units must be wrong.
PLAUSIBLE_C = (-100.0, 300.0)


def plausible_c(value: float) -> bool:
    """A temperature a chamber's air could have."""
    return math.isfinite(value) and PLAUSIBLE_C[0] <= value <= PLAUSIBLE_C[1]


class LimitedChamber:
    """Refuses setpoints outside the rig's chamber limits, and outside the controller's own where it exposes
    them (read once, at connect: a controller clamps silently what it will not take); verifies each write by
    reading back. A set point is first rounded to what the controller holds (a 0.1 °C register or template),
    so the value checked against the limits and read back is the one on the wire."""

    def __init__(self, chamber: Chamber, limits: ChamberConfig) -> None:
        self._chamber = chamber
        self._limits = limits
        self.endpoint = chamber.endpoint
        self.controller_limits = controller_limits(chamber)
        self.setpoint_decimals = setpoint_decimals(chamber)

    def controller_limits_c(self) -> tuple[float, float] | None:
        return self.controller_limits

    def write_setpoint_c(self, setpoint_c: float) -> None:
        if self.setpoint_decimals is not None:
            setpoint_c = round(setpoint_c, self.setpoint_decimals)
        low, high = self._limits.min_setpoint_c, self._limits.max_setpoint_c
        if not low <= setpoint_c <= high:
            raise InstrumentError(
                f"chamber ({self.endpoint}): setpoint {setpoint_c:g} °C refused, limits are {low:g}…{high:g} °C"
            )
        if self.controller_limits is not None:
            controller_low, controller_high = self.controller_limits
            if not controller_low <= setpoint_c <= controller_high:
                raise InstrumentError(f"chamber ({self.endpoint}): setpoint {setpoint_c:g} °C refused, the "
                                      f"controller's own limits are {controller_low:g}…{controller_high:g} °C")
        self._chamber.write_setpoint_c(setpoint_c)
        readback = self._chamber.read_setpoint_c()
        if abs(readback - setpoint_c) > SETPOINT_READBACK_TOLERANCE_C:
            raise InstrumentError(
                f"chamber ({self.endpoint}): setpoint {setpoint_c:g} °C written but {readback:g} °C read back"
            )

    def __getattr__(self, name: str):
        return getattr(self._chamber, name)


class LimitedTurntable:
    """Refuses moves outside the axis limits (continuous axes excepted) or with the wrong axis count."""

    def __init__(self, turntable: Turntable, config: TurntableConfig) -> None:
        self._turntable = turntable
        self._axes = config.axes
        self.endpoint = turntable.endpoint

    def move_to(self, angles_deg: np.ndarray) -> None:
        angles = np.asarray(angles_deg, dtype=float)
        if angles.shape != (len(self._axes),):
            raise InstrumentError(f"turntable ({self.endpoint}): {angles.size} angles for {len(self._axes)} axes")
        for axis, angle in zip(self._axes, angles):
            if not axis.allows(angle):
                raise InstrumentError(
                    f"turntable ({self.endpoint}): axis {axis.name} to {angle:g}° refused, "
                    f"limits are {axis.min_deg:g}…{axis.max_deg:g}°"
                )
        self._turntable.move_to(angles)

    def __getattr__(self, name: str):
        return getattr(self._turntable, name)
