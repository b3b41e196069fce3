"""`rig check`: contact every instrument of a rig and describe it in one line, before a campaign."""

from __future__ import annotations

from collections.abc import Iterator

from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.humidity import dew_point_c
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import (
    AlarmReporting,
    ConstantRateRotation,
    controller_limits,
    has_purge,
    humidity_pct,
)
from accelcal_rig.instruments.connect import SomeInstruments
from accelcal_rig.instruments.interfaces import Chamber, Turntable


def check_lines(instruments: SomeInstruments, rig: RigConfig) -> Iterator[str]:
    """One line per instrument connected; the first wrong answer raises InstrumentError naming it."""
    chamber, turntable = instruments.chamber, instruments.turntable
    if chamber is not None:
        controller = controller_limits(chamber)
        limits = (f"; set point limits: the rig's {rig.chamber.min_setpoint_c:g}…{rig.chamber.max_setpoint_c:g} °C, "
                  "the " + (f"controller's {controller[0]:g}…{controller[1]:g} °C" if controller
                            else "controller exposes none"))
        yield f"chamber    {chamber.endpoint}: {chamber.identify()}{_alarm(chamber)}{limits}{_moisture(chamber, rig)}"
    if turntable is not None:
        angles = " ".join(f"{a:.3f}" for a in turntable.read_angles_deg())
        yield (f"turntable  {turntable.endpoint}: {turntable.identify()}, angles {angles}°, "
               f"{'in position' if _at_rest(turntable) else 'moving'}{_rates(turntable, rig)}")
    for sensor in instruments.sensors:
        identity = sensor.identify()
        wrong = sensor.part.wrong_identity(identity.registers)
        if wrong:
            raise InstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): {wrong}")
        ranges, odr_hz = sensor.read_settings()
        yield (f"sensor {sensor.serial}  {sensor.endpoint}: {identity.describe(sensor.part.label)}, "
               f"{sensor.part.describe_ranges(ranges)}, "
               f"{odr_hz:g} Hz, {sensor.read_temperature_c():.1f} °C")


def _rates(turntable: Turntable, rig: RigConfig) -> str:
    """The rates of the axes the rig config gives a rate mode, where the profile can read them; nothing else
    (a table without rate mode, or a rig that states none, is not asked)."""
    axes = [(index, axis.name) for index, axis in enumerate(rig.turntable.axes) if axis.max_rate_dps is not None]
    if not axes or not isinstance(turntable, ConstantRateRotation):
        return ""
    return ", rates " + " ".join(f"{name} {turntable.read_rate_deg_s(index):.3f}" for index, name in axes) + " °/s"


def _alarm(chamber: Chamber) -> str:
    """The controller's alarm, where its profile can ask; nothing where it cannot (not "clear": not known)."""
    if not isinstance(chamber, AlarmReporting):
        return ""
    return f", alarm {'ACTIVE' if chamber.alarm_active() else 'clear'}"


def _at_rest(turntable: Turntable) -> bool:
    """In position: asked a few times, as a profile that judges completion by rate wants polls in a row."""
    return any(turntable.in_position() for _ in range(_REST_POLLS))


#: At most this many in-position polls for `rig check` (the built-in profiles want at most three).
_REST_POLLS = 5


def _moisture(chamber: Chamber, rig: RigConfig) -> str:
    """What a procedure's frost settings can count on: the dew point a campaign would use (the configured
    one wins; else the controller's humidity reading, which a temperature-only chamber may refuse), and
    whether there is a purge output."""
    if rig.chamber.dew_point_c is not None:
        air = f"dew point {rig.chamber.dew_point_c:g} °C configured"
    else:
        try:
            relative_humidity = humidity_pct(chamber)
        except InstrumentError as exc:
            relative_humidity, air = None, f"humidity not read ({exc})"
        else:
            air = "no humidity reading"
        if relative_humidity is not None:
            dew = dew_point_c(chamber.read_temperature_c(), relative_humidity)
            air = f"{relative_humidity:.1f} % RH (dew point {dew:.1f} °C)"
    return f"; {air}; dry-air purge {'output' if has_purge(chamber) else 'none'}"
