"""Open every instrument of a rig config with the driver its `driver:` names (accelcal_rig.plugins), at
given endpoints."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from accelcal_rig.config.load import LoadedConfig
from accelcal_rig.config.rig import RigConfig, SensorConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import ConfigError
from accelcal_rig.instruments.interfaces import Chamber, RigInstruments, Sensor, Turntable, close_each
from accelcal_rig.parts.part import Part
from accelcal_rig.parts.registry import part
from accelcal_rig.plugins import load_driver, load_object


@dataclass(frozen=True)
class Endpoints:
    """Where each instrument answers; `drivers` the drivers to reach them with where not the rig config's
    (keys `chamber`, `turntable` and sensor serials: a dry run's simulators may want another)."""

    chamber: str
    turntable: str
    sensors: dict[str, str] = field(default_factory=dict)
    drivers: dict[str, str] = field(default_factory=dict)


#: The instruments of a rig, as `rig check --only` names them.
INSTRUMENTS = ("chamber", "turntable", "sensors")
EVERY_INSTRUMENT = frozenset(INSTRUMENTS)


@dataclass
class SomeInstruments:
    """The instruments of a rig that were asked for (`rig check --only`); the others are None or empty."""

    chamber: Chamber | None
    turntable: Turntable | None
    sensors: list[Sensor]

    def close(self) -> list[str]:
        """Release every connection, each in its own guard; return the failures, one line each."""
        return close_each(self.chamber, self.turntable, self.sensors)


def configured_endpoints(rig: LoadedConfig[RigConfig], only: frozenset[str] = EVERY_INSTRUMENT) -> Endpoints:
    """The endpoints the rig config names for the instruments in `only`; a missing one is an error pointing
    at its key."""
    for problem in missing_endpoints(rig, only).values():
        raise problem
    return named_endpoints(rig.model, only)


def missing_endpoints(rig: LoadedConfig[RigConfig], only: frozenset[str] = EVERY_INSTRUMENT) -> dict[str, ConfigError]:
    """Each instrument in `only` whose endpoint the rig config leaves out (`chamber`, `turntable`, a sensor's
    serial) → the error pointing at its key, in the rig's order."""
    model = rig.model
    missing = "no endpoint given: set it, or run with --dry-run to simulate this rig"
    problems = {}
    if "chamber" in only and not model.chamber.endpoint:
        problems["chamber"] = rig.error(("chamber", "endpoint"), missing)
    if "turntable" in only and not model.turntable.endpoint:
        problems["turntable"] = rig.error(("turntable", "endpoint"), missing)
    for index, sensor in enumerate(model.fixture.sensors if "sensors" in only else []):
        if not sensor.endpoint:
            problems[sensor.serial] = rig.error(("fixture", "sensors", index, "endpoint"), missing)
    return problems


def named_endpoints(model: RigConfig, only: frozenset[str] = EVERY_INSTRUMENT) -> Endpoints:
    """The endpoints the rig config names (an empty one where it names none: see missing_endpoints)."""
    sensors = {sensor.serial: sensor.endpoint or "" for sensor in (model.fixture.sensors if "sensors" in only else [])}
    return Endpoints(model.chamber.endpoint or "", model.turntable.endpoint or "", sensors)


def open_chamber(rig: RigConfig, endpoints: Endpoints) -> Chamber:
    """The chamber, through the driver its config (or the dry run) names."""
    chamber: Chamber = load_driver("chamber", endpoints.drivers.get("chamber", rig.chamber.driver)).open(
        rig.chamber, endpoints.chamber)
    return chamber


def open_turntable(rig: RigConfig, endpoints: Endpoints) -> Turntable:
    """The turntable, through the driver its config (or the dry run) names."""
    turntable: Turntable = load_driver("turntable", endpoints.drivers.get("turntable", rig.turntable.driver)).open(
        rig.turntable, endpoints.turntable)
    return turntable


def open_sensor(rig: RigConfig, sensor: SensorConfig, endpoints: Endpoints, clock: Clock) -> Sensor:
    """One DUT: its transport through the driver its config names, spoken as its part says."""
    transport = load_driver("sensor", endpoints.drivers.get(sensor.serial, sensor.driver)).open(
        sensor, endpoints.sensors[sensor.serial], rig.retry.attempts, clock)
    return sensor_device(transport, sensor.serial, clock, part(sensor.part))


def connect_some(rig: RigConfig, endpoints: Endpoints, clock: Clock,
                 only: frozenset[str] = EVERY_INSTRUMENT) -> SomeInstruments:
    """Open the instruments in `only`; if one fails, close those already open and raise."""
    opened: list[Any] = []
    chamber = turntable = None
    try:
        if "chamber" in only:
            chamber = open_chamber(rig, endpoints)
            opened.append(chamber)
        if "turntable" in only:
            turntable = open_turntable(rig, endpoints)
            opened.append(turntable)
        sensors: list[Sensor] = []
        for sensor in rig.fixture.sensors if "sensors" in only else []:
            sensors.append(open_sensor(rig, sensor, endpoints, clock))
            opened.append(sensors[-1])
    except BaseException:
        for device in opened:
            device.close()
        raise
    return SomeInstruments(chamber, turntable, sensors)


def sensor_device(transport: Any, serial: str, clock: Clock, dut_part: Part) -> Sensor:
    """The DUT as the driver its part names speaks it, over `transport`: the device is built from the part."""
    device = load_object(dut_part.device, f"part {dut_part.name!r}'s device")
    return device(transport, serial, clock, dut_part)  # type: ignore[no-any-return]


def connect_rig(rig: RigConfig, endpoints: Endpoints, clock: Clock) -> RigInstruments:
    """Open chamber, turntable and every sensor; if one fails, close those already open and raise."""
    some = connect_some(rig, endpoints, clock)
    assert some.chamber is not None and some.turntable is not None
    return RigInstruments(some.chamber, some.turntable, some.sensors)
