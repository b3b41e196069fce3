"""Write-safety gates in front of any driver: nothing outside the rig's limits reaches the wire."""

from __future__ import annotations

import math

import numpy as np

from accelcal_rig.config.rig import ChamberConfig, TurntableConfig
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import (
    ConstantRateRotation,
    ControllerLimits,
    SetpointResolution,
    controller_limits,
    setpoint_decimals,
)
from accelcal_rig.instruments.delegates import (
    CHAMBER_CAPABILITIES,
    TURNTABLE_CAPABILITIES,
    ChamberDelegate,
    PassRateRotation,
    TurntableDelegate,
)
from accelcal_rig.instruments.interfaces import Chamber, Turntable

#: A setpoint read back further than this from what was written means the controller did not take it.
SETPOINT_READBACK_TOLERANCE_C = 0.05
#: Readings outside this are not a chamber's air: the map, word order, profile or units must be wrong.
PLAUSIBLE_C = (-100.0, 300.0)


def plausible_c(value: float) -> bool:
    """A temperature a chamber's air could have."""
    return math.isfinite(value) and PLAUSIBLE_C[0] <= value <= PLAUSIBLE_C[1]


def refuse_non_finite(instrument: str, what: str, value: float, unit: str) -> None:
    """A NaN or an infinity is never sent (a controller would take it as garbage, or as its own idea of a
    limit): one line naming the instrument, before the wire. Every driver's writes call it, so a driver used
    without the limits in front of it (a plug-in's test, a script) is as safe."""
    if not math.isfinite(value):
        raise InstrumentError(f"{instrument}: {what} {value:g}{unit} refused: not a finite number (nothing was sent)")


class LimitedChamber(ChamberDelegate):
    """Refuses setpoints outside the rig's chamber limits, and outside the controller's own where it exposes
    them (read once, at connect: a controller clamps silently what it will not take); verifies each write by
    reading back, whether the controller clamps (the Modbus and SIMSERV simulators acknowledge and clamp) or
    ignores (an SCPI setting is unanswered) what it will not take. A set point is first rounded to what the
    controller holds (a 0.1 °C register or template), so the value checked against the limits and read back
    is the one on the wire. Everything else is passed on, with the capabilities of the chamber it guards and
    no others."""

    def __init__(self, chamber: Chamber, limits: ChamberConfig) -> None:
        super().__init__(chamber)
        self._limits = limits
        self.controller_limits = controller_limits(chamber)
        self._decimals = setpoint_decimals(chamber)

    def write_setpoint_c(self, setpoint_c: float) -> None:
        refuse_non_finite(f"chamber ({self.endpoint})", "setpoint", setpoint_c, " °C")
        if self._decimals is not None:
            setpoint_c = round(setpoint_c, self._decimals)
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
            raise InstrumentError(f"chamber ({self.endpoint}): set point {setpoint_c:g} °C written, the controller "
                                  f"holds {readback:g} °C (it clamped or refused it)")


class _LimitsReadAtConnect(LimitedChamber):
    def controller_limits_c(self) -> tuple[float, float] | None:
        return self.controller_limits


class _DecimalsReadAtConnect(LimitedChamber):
    @property
    def setpoint_decimals(self) -> int:
        assert self._decimals is not None  # composed in only for a chamber with a set point resolution
        return self._decimals


LimitedChamber._passes_on = {**CHAMBER_CAPABILITIES, ControllerLimits: _LimitsReadAtConnect,
                             SetpointResolution: _DecimalsReadAtConnect}


class LimitedTurntable(TurntableDelegate):
    """Refuses moves outside the axis limits (continuous axes excepted) or with the wrong axis count, and, on
    a rate table, a rate or acceleration beyond the axis's rate limits or constant-rate rotation of an axis
    without rate limits or without a slip ring; the rest is passed on."""

    def __init__(self, turntable: Turntable, config: TurntableConfig) -> None:
        super().__init__(turntable)
        self._axes = config.axes

    def move_to(self, angles_deg: np.ndarray) -> None:
        angles = np.asarray(angles_deg, dtype=float)
        if angles.shape != (len(self._axes),):
            raise InstrumentError(f"turntable ({self.endpoint}): {angles.size} angles for {len(self._axes)} axes")
        for axis, angle in zip(self._axes, angles):
            refuse_non_finite(f"turntable ({self.endpoint})", f"axis {axis.name} to", angle, "°")
            if not axis.allows(angle):
                raise InstrumentError(
                    f"turntable ({self.endpoint}): axis {axis.name} to {angle:g}° refused, "
                    f"limits are {axis.min_deg:g}…{axis.max_deg:g}°"
                )
        self._turntable.move_to(angles)


class _LimitedRate(LimitedTurntable, PassRateRotation):
    def rotate_at(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        if not 0 <= axis < len(self._axes):
            raise InstrumentError(f"turntable ({self.endpoint}): no axis {axis} (the rig has {len(self._axes)})")
        limits = self._axes[axis]
        refused = f"turntable ({self.endpoint}): axis {limits.name} at {rate_deg_s:g} °/s refused"
        if limits.max_rate_dps is None or limits.max_acceleration_dps2 is None:
            raise InstrumentError(f"{refused}: the rig config gives it no rate mode (max_rate_dps, "
                                  "max_acceleration_dps2)")
        if not limits.slip_ring:
            raise InstrumentError(f"{refused}: it has no slip ring (slip_ring: false), so it cannot turn "
                                  "continuously")
        if not (math.isfinite(rate_deg_s) and abs(rate_deg_s) <= limits.max_rate_dps):
            raise InstrumentError(f"{refused}: beyond its max_rate_dps {limits.max_rate_dps:g} °/s")
        if not (math.isfinite(acceleration_deg_s2) and 0 < acceleration_deg_s2 <= limits.max_acceleration_dps2):
            raise InstrumentError(f"{refused}: acceleration {acceleration_deg_s2:g} °/s² beyond its "
                                  f"max_acceleration_dps2 {limits.max_acceleration_dps2:g} °/s²")
        super().rotate_at(axis, rate_deg_s, acceleration_deg_s2)


LimitedTurntable._passes_on = {**TURNTABLE_CAPABILITIES, ConstantRateRotation: _LimitedRate}
