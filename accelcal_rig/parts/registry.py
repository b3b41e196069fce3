"""Parts by name: the built-in ones, and any a third-party package registers under the entry-point group
`accelcal_rig.parts` (an entry point's object is a `Part`)."""

from __future__ import annotations

from functools import cache
from importlib.metadata import entry_points

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.errors import ConfigError
from accelcal_rig.parts.adxl35x import ADXL355, ADXL357, ADXL359
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.lis3mdl import LIS3MDL
from accelcal_rig.parts.part import Part

ENTRY_POINT_GROUP = "accelcal_rig.parts"
DEFAULT_PART = "adxl355"
_BUILT_IN = {part.name: part for part in (ADXL355, ADXL357, ADXL359, ICM42688P, LIS3MDL)}


@cache
def known_parts() -> dict[str, Part]:
    """Every part by name; a built-in name cannot be taken over by a plug-in (a warning names one that tries)."""
    parts = {}
    for entry in entry_points(group=ENTRY_POINT_GROUP):
        if entry.name in _BUILT_IN:  # said, not silently passed over: the lab meant the plug-in's
            LOGGER.warning("part plug-in %r (%s) is not used: a built-in part has that name", entry.name, entry.value)
            continue
        try:
            part = entry.load()
        except Exception as exc:  # noqa: BLE001 - a broken plug-in is one line naming it, not a traceback
            raise ConfigError(f"part plug-in {entry.name!r} ({entry.value}): cannot load: {exc}") from None
        if not (isinstance(part, Part) and part.name == entry.name):
            raise ConfigError(f"part plug-in {entry.name!r} ({entry.value}): not a Part named "
                              f"{entry.name!r}")
        parts[entry.name] = part
    return {**parts, **_BUILT_IN}


def part(name: str) -> Part:
    """The part called `name`; KeyError names the ones known."""
    parts = known_parts()
    if name not in parts:
        raise KeyError(f"unknown part {name!r} (known: {', '.join(sorted(parts))})")
    return parts[name]
