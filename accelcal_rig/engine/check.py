"""`rig check`: contact every instrument of a rig and describe it in one line, before a campaign. Each is
opened, asked and closed on its own, so a dead turntable port says nothing against the chamber or the
sensors: every instrument gets its line, OK or its failure."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TypeVar

from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.humidity import dew_point_c
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.errors import InstrumentError, RigError
from accelcal_rig.instruments.capabilities import (
    AlarmReporting,
    ConstantRateRotation,
    controller_limits,
    has_purge,
    humidity_pct,
)
from accelcal_rig.instruments.connect import Endpoints, open_chamber, open_sensor, open_turntable
from accelcal_rig.instruments.interfaces import Chamber, Sensor, Turntable

Device = TypeVar("Device", Chamber, Turntable, Sensor)


@dataclass(frozen=True)
class InstrumentCheck:
    """One instrument's answer to `rig check`: what it said, or why it could not be checked."""

    name: str  # `chamber`, `turntable`, `sensor <serial>`
    ok: bool
    text: str


def check_instruments(rig: RigConfig, endpoints: Endpoints, clock: Clock, only: frozenset[str],
                      missing: dict[str, RigError]) -> Iterator[InstrumentCheck]:
    """Each instrument in `only`, in the rig's order, opened, described and closed on its own; one whose
    endpoint is `missing` (chamber, turntable or a serial → the error) or that fails is a failed check, and
    the next is checked all the same."""
    if "chamber" in only:
        yield _checked("chamber", missing.get("chamber"), lambda: open_chamber(rig, endpoints),
                       lambda chamber: describe_chamber(chamber, rig))
    if "turntable" in only:
        yield _checked("turntable", missing.get("turntable"), lambda: open_turntable(rig, endpoints),
                       lambda turntable: describe_turntable(turntable, rig))
    for sensor in rig.fixture.sensors if "sensors" in only else []:
        yield _checked(f"sensor {sensor.serial}", missing.get(sensor.serial),
                       lambda sensor=sensor: open_sensor(rig, sensor, endpoints, clock), describe_sensor)  # type: ignore[misc]


def _checked(name: str, missing: RigError | None, open_device: Callable[[], Device],
             describe: Callable[[Device], str]) -> InstrumentCheck:
    if missing is not None:
        return InstrumentCheck(name, False, str(missing))
    try:
        device = open_device()
    except RigError as exc:
        return InstrumentCheck(name, False, _one_line(exc))
    try:
        return InstrumentCheck(name, True, describe(device))
    except RigError as exc:
        return InstrumentCheck(name, False, _one_line(exc))
    finally:
        try:
            device.close()
        except Exception as exc:  # noqa: BLE001 - a port that will not close is logged; the answer stands
            LOGGER.error(f"{name} ({device.endpoint}): close failed: {exc}")


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def describe_chamber(chamber: Chamber, rig: RigConfig) -> str:
    """Its endpoint, identity, alarm (where its profile can ask), set point limits and what frost settings
    can count on."""
    controller = controller_limits(chamber)
    limits = (f"; set point limits: the rig's {rig.chamber.min_setpoint_c:g}…{rig.chamber.max_setpoint_c:g} °C, "
              "the " + (f"controller's {controller[0]:g}…{controller[1]:g} °C" if controller
                        else "controller exposes none"))
    return f"{chamber.endpoint}: {chamber.identify()}{_alarm(chamber)}{limits}{_moisture(chamber, rig)}"


def describe_turntable(turntable: Turntable, rig: RigConfig) -> str:
    """Its endpoint, identity, angles, whether in position, the rates of the axes given a rate mode, and for an
    ACL controller whether it acknowledges every command (a controller doing otherwise than the rig config says
    has failed the identity already, naming the override)."""
    angles = " ".join(f"{a:.3f}" for a in turntable.read_angles_deg())
    return (f"{turntable.endpoint}: {turntable.identify()}, angles {angles}°, "
            f"{'in position' if _at_rest(turntable) else 'moving'}{_rates(turntable, rig)}{_acknowledgements(rig)}")


def _acknowledgements(rig: RigConfig) -> str:
    if rig.turntable is None or rig.turntable.driver != "serial":
        return ""
    protocol = rig.turntable.line_protocol()
    if protocol.dialect != "acl":
        return ""
    if protocol.acknowledgement == "length-prefixed":
        return ", acknowledges every command (length-prefixed: an error code and a length before each answer)"
    return ", answers queries only (no acknowledgements, as on GPIB)"


def describe_sensor(sensor: Sensor) -> str:
    """Its endpoint, identity (refused if not its part's), ranges, data rate and temperature."""
    identity = sensor.identify()
    wrong = sensor.part.wrong_identity(identity.registers)
    if wrong:
        raise InstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): {wrong}")
    ranges, odr_hz = sensor.read_settings()
    return (f"{sensor.endpoint}: {identity.describe(sensor.part.label)}, {sensor.part.describe_ranges(ranges)}, "
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
