"""Typed stand-ins for an instrument (the write-safety limits, the retries): each passes every call of the
core protocol on through `_through` (directly here; a subclass retries it) and has a capability exactly
when the instrument it wraps has it, so `isinstance(wrapper, Purging)` is `isinstance(inner, Purging)`.

A subclass may pass a capability on its own way: `_passes_on` maps each capability to the mixin (a subclass
of the delegate) that carries its methods.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Self, TypeVar, cast

import numpy as np

from accelcal_rig.instruments.capabilities import (
    AlarmReporting,
    ConstantRateRotation,
    ControllerLimits,
    HumiditySensing,
    Purging,
    Reconnecting,
    SetpointResolution,
)
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.interfaces import Chamber, Turntable

T = TypeVar("T")


class ChamberDelegate:
    """Stands in for `chamber`: the core members passed on, each capability only where it has one."""

    _passes_on: ClassVar[Mapping[type, type[ChamberDelegate]]] = {}

    def __new__(cls, chamber: Chamber, *args: Any, **kwargs: Any) -> Self:
        mixins = [mixin for capability, mixin in cls._passes_on.items() if isinstance(chamber, capability)]
        return instance_of(composed(cls, mixins))

    def __init__(self, chamber: Chamber) -> None:
        self._chamber = chamber
        self.endpoint = chamber.endpoint

    def _through(self, operation: Callable[[], T]) -> T:
        """Run one call on the instrument (a subclass retries it)."""
        return operation()

    def identify(self) -> str:
        return self._through(self._chamber.identify)

    def read_temperature_c(self) -> float:
        return self._through(self._chamber.read_temperature_c)

    def write_setpoint_c(self, setpoint_c: float) -> None:
        self._through(lambda: self._chamber.write_setpoint_c(setpoint_c))

    def read_setpoint_c(self) -> float:
        return self._through(self._chamber.read_setpoint_c)

    def set_power(self, on: bool) -> None:
        self._through(lambda: self._chamber.set_power(on))

    def close(self) -> None:
        self._chamber.close()


# Each mixin is composed in only where the chamber has the capability: the casts say what was checked.
class PassAlarm(ChamberDelegate):
    def alarm_active(self) -> bool:
        return self._through(cast(AlarmReporting, self._chamber).alarm_active)


class PassControllerLimits(ChamberDelegate):
    def controller_limits_c(self) -> tuple[float, float] | None:
        return self._through(cast(ControllerLimits, self._chamber).controller_limits_c)


class PassPurge(ChamberDelegate):
    def set_purge(self, on: bool) -> None:
        self._through(lambda: cast(Purging, self._chamber).set_purge(on))


class PassHumidity(ChamberDelegate):
    def read_humidity_pct(self) -> float | None:
        return self._through(cast(HumiditySensing, self._chamber).read_humidity_pct)


class PassResolution(ChamberDelegate):
    @property
    def setpoint_decimals(self) -> int:
        return cast(SetpointResolution, self._chamber).setpoint_decimals


class PassChamberReconnect(ChamberDelegate):
    def reconnect(self) -> None:
        cast(Reconnecting, self._chamber).reconnect()


#: Every chamber capability a delegate passes on, and how.
CHAMBER_CAPABILITIES: Mapping[type, type[ChamberDelegate]] = {
    AlarmReporting: PassAlarm, ControllerLimits: PassControllerLimits, Purging: PassPurge,
    HumiditySensing: PassHumidity, SetpointResolution: PassResolution, Reconnecting: PassChamberReconnect}
ChamberDelegate._passes_on = CHAMBER_CAPABILITIES


class TurntableDelegate:
    """Stands in for `turntable`: the core members passed on, each capability only where it has one."""

    _passes_on: ClassVar[Mapping[type, type[TurntableDelegate]]] = {}

    def __new__(cls, turntable: Turntable, *args: Any, **kwargs: Any) -> Self:
        mixins = [mixin for capability, mixin in cls._passes_on.items() if isinstance(turntable, capability)]
        return instance_of(composed(cls, mixins))

    def __init__(self, turntable: Turntable) -> None:
        self._turntable = turntable
        self.endpoint = turntable.endpoint

    def _through(self, operation: Callable[[], T]) -> T:
        """Run one call on the instrument (a subclass retries it)."""
        return operation()

    def identify(self) -> str:
        return self._through(self._turntable.identify)

    def move_to(self, angles_deg: np.ndarray) -> None:
        self._through(lambda: self._turntable.move_to(angles_deg))

    def read_angles_deg(self) -> np.ndarray:
        return self._through(self._turntable.read_angles_deg)

    def in_position(self) -> bool:
        return self._through(self._turntable.in_position)

    def stop(self) -> None:
        self._through(self._turntable.stop)

    def close(self) -> None:
        self._turntable.close()


class PassTurntableReconnect(TurntableDelegate):
    def reconnect(self) -> None:
        cast(Reconnecting, self._turntable).reconnect()


class PassRateRotation(TurntableDelegate):
    def rotate_at(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        self._through(lambda: cast(ConstantRateRotation, self._turntable).rotate_at(axis, rate_deg_s,
                                                                                     acceleration_deg_s2))

    def read_rate_deg_s(self, axis: int) -> float:
        return self._through(lambda: cast(ConstantRateRotation, self._turntable).read_rate_deg_s(axis))

    def hold(self, axis: int) -> None:
        self._through(lambda: cast(ConstantRateRotation, self._turntable).hold(axis))


#: Every turntable capability a delegate passes on, and how.
TURNTABLE_CAPABILITIES: Mapping[type, type[TurntableDelegate]] = {Reconnecting: PassTurntableReconnect,
                                                                  ConstantRateRotation: PassRateRotation}
TurntableDelegate._passes_on = TURNTABLE_CAPABILITIES
