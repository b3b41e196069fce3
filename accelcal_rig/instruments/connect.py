"""Open every instrument of a rig config with the driver its `driver:` names (accelcal_rig.plugins), at
given endpoints."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from accelcal_rig.config.load import LoadedConfig
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.interfaces import RigInstruments
from accelcal_rig.parts.registry import part
from accelcal_rig.plugins import load_driver


@dataclass(frozen=True)
class Endpoints:
    """Where each instrument answers; `drivers` the drivers to reach them with where not the rig config's
    (keys `chamber`, `turntable` and sensor serials: a dry run's simulators may want another)."""

    chamber: str
    turntable: str
    sensors: dict[str, str] = field(default_factory=dict)
    drivers: dict[str, str] = field(default_factory=dict)


def configured_endpoints(rig: LoadedConfig[RigConfig]) -> Endpoints:
    """The endpoints the rig config names; a missing one is an error pointing at its key."""
    model = rig.model
    missing = "no endpoint given: set it, or run with --dry-run to simulate this rig"
    if not model.chamber.endpoint:
        raise rig.error(("chamber", "endpoint"), missing)
    if not model.turntable.endpoint:
        raise rig.error(("turntable", "endpoint"), missing)
    sensors = {}
    for index, sensor in enumerate(model.fixture.sensors):
        if not sensor.endpoint:
            raise rig.error(("fixture", "sensors", index, "endpoint"), missing)
        sensors[sensor.serial] = sensor.endpoint
    return Endpoints(model.chamber.endpoint, model.turntable.endpoint, sensors)


def connect_rig(rig: RigConfig, endpoints: Endpoints, clock: Clock) -> RigInstruments:
    """Open chamber, turntable and every sensor; if one fails, close those already open and raise."""
    drivers = endpoints.drivers
    opened: list[Any] = []
    try:
        opened.append(load_driver("chamber", drivers.get("chamber", rig.chamber.driver)).open(
            rig.chamber, endpoints.chamber))
        opened.append(load_driver("turntable", drivers.get("turntable", rig.turntable.driver)).open(
            rig.turntable, endpoints.turntable))
        for sensor in rig.fixture.sensors:
            transport = load_driver("sensor", drivers.get(sensor.serial, sensor.driver)).open(
                sensor, endpoints.sensors[sensor.serial], rig.retry.attempts, clock)
            opened.append(Adxl355(transport, sensor.serial, clock, part(sensor.part)))
    except BaseException:
        for device in opened:
            device.close()
        raise
    return RigInstruments(opened[0], opened[1], opened[2:])
