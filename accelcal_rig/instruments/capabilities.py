"""What only some chamber drivers can do, asked without assuming it: a plug-in driver written before these
existed simply has none of them."""

from __future__ import annotations

from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.interfaces import Chamber


def controller_limits(chamber: Chamber) -> tuple[float, float] | None:
    """The controller's own set point limits; None from a driver that cannot read them."""
    limits = getattr(chamber, "controller_limits_c", None)
    return limits() if callable(limits) else None


def has_purge(chamber: Chamber) -> bool:
    """Whether the chamber's driver (and its profile) can switch a dry-air purge."""
    available = getattr(chamber, "has_purge", None)
    return bool(available()) if callable(available) else False


def set_purge(chamber: Chamber, on: bool) -> None:
    if not has_purge(chamber):
        raise InstrumentError(f"chamber ({chamber.endpoint}): no dry-air purge output (its profile names none)")
    chamber.set_purge(on)  # type: ignore[attr-defined]


def humidity_pct(chamber: Chamber) -> float | None:
    """The controller's relative humidity reading; None where it has none."""
    read = getattr(chamber, "read_humidity_pct", None)
    return read() if callable(read) else None


def setpoint_decimals(chamber: Chamber) -> int | None:
    """The decimals a chamber's set point is written with (a 16-bit register's, a template's `.1f`); None:
    written in full."""
    decimals = getattr(chamber, "setpoint_decimals", None)
    return decimals if isinstance(decimals, int) else None
