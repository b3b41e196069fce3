"""Drivers by name: the built-in ones, and those third-party packages register through entry points.

A rig config's `driver:` names one. Entry-point groups: `accelcal_rig.chambers`, `accelcal_rig.turntables`,
`accelcal_rig.sensors` (each entry point's object a ChamberDriver, TurntableDriver or SensorDriver of
`accelcal_rig.instruments.definitions`, which names its simulator and its protocol), and
`accelcal_rig.parts` (see accelcal_rig.parts.registry). Nothing of a driver is imported until a rig uses it.
"""

from __future__ import annotations

import importlib
from functools import cache
from importlib.metadata import entry_points
from typing import Any, Literal

from accelcal_rig.errors import ConfigError

Kind = Literal["chamber", "turntable", "sensor"]
GROUPS: dict[str, str] = {"chamber": "accelcal_rig.chambers", "turntable": "accelcal_rig.turntables",
                          "sensor": "accelcal_rig.sensors"}
_BUILT_IN: dict[str, dict[str, str]] = {
    "chamber": {"modbus-tcp": "accelcal_rig.instruments.chamber_modbus:MODBUS_TCP",
                "modbus-rtu": "accelcal_rig.instruments.chamber_modbus:MODBUS_RTU",
                "line": "accelcal_rig.instruments.chamber_line:LINE"},
    "turntable": {"serial": "accelcal_rig.instruments.turntable_serial:SERIAL"},
    "sensor": {"serial-bridge": "accelcal_rig.instruments.sensor_links:SERIAL_BRIDGE",
               "spidev": "accelcal_rig.instruments.sensor_links:SPIDEV"},
}


@cache
def drivers(kind: Kind) -> dict[str, str]:
    """Every `kind` driver's name → where its definition is ("module:attribute"); built-in names win."""
    found = {entry.name: entry.value for entry in entry_points(group=GROUPS[kind])}
    return {**found, **_BUILT_IN[kind]}


def driver_problem(kind: Kind, name: str) -> str | None:
    """Why `name` is not a `kind` driver; None when it is."""
    known = drivers(kind)
    if name in known:
        return None
    return f"unknown {kind} driver {name!r} (known: {', '.join(sorted(known))})"


def load_driver(kind: Kind, name: str) -> Any:
    """The definition of the `kind` driver `name`, imported now."""
    problem = driver_problem(kind, name)
    if problem:
        raise ConfigError(problem)
    return load_object(drivers(kind)[name], f"{kind} driver {name!r}")


def load_object(reference: str, what: str) -> Any:
    """The object a "module:attribute" reference names; one line naming `what` when it cannot be loaded."""
    module, _, attribute = reference.partition(":")
    try:
        return getattr(importlib.import_module(module), attribute)
    except Exception as exc:  # noqa: BLE001 - a broken plug-in is one line naming it, not a traceback
        raise ConfigError(f"{what}: cannot load {reference}: {exc}") from None
