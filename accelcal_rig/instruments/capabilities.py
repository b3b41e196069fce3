"""What only some instruments can do, as small protocols asked with `isinstance` (bluesky's `protocols.py` is
the model): a driver has a capability exactly when its profile (or the instrument it wraps) has the
feature, so nothing answers for a feature that is not there (an alarm never asked is not "clear"), and a
plug-in driver without a member simply lacks that capability.

The helpers below are how the engine asks a chamber; each answers for a chamber without the capability.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.interfaces import Chamber, SampleBlock

#: `call(operation, reconnect)`: run `operation`, retrying transient failures, reconnecting with `reconnect`.
RetryCall = Callable[[Callable[[], Any], Callable[[], None] | None], Any]

# ---------------------------------------------------------------------- chambers


@runtime_checkable
class AlarmReporting(Protocol):
    """A controller whose alarm can be queried (a profile without an alarm query has no such answer)."""

    def alarm_active(self) -> bool: ...


@runtime_checkable
class ControllerLimits(Protocol):
    """A controller that says its own set point limits (it clamps silently what it will not take)."""

    def controller_limits_c(self) -> tuple[float, float] | None: ...


@runtime_checkable
class Purging(Protocol):
    """A chamber with a dry-air purge output (frost and condensation on a cold fixture)."""

    def set_purge(self, on: bool) -> None: ...


@runtime_checkable
class HumiditySensing(Protocol):
    """A chamber that reads its air's relative humidity."""

    def read_humidity_pct(self) -> float | None: ...


@runtime_checkable
class SetpointResolution(Protocol):
    """A controller that holds its set point to a few decimals (a 16-bit register, a `.1f` template): the
    limit gate rounds to them first, so the value checked and read back is the one on the wire."""

    @property
    def setpoint_decimals(self) -> int: ...


# ---------------------------------------------------------------------- turntables (every one is Positioning)


@runtime_checkable
class ConstantRateRotation(Protocol):
    """Turns an axis at a constant rate (a rate table: a gyroscope's reference): `axis` is the index of the
    rig config's axis (0 is the outermost). `rotate_at` reaches `rate_deg_s` (signed) at
    `acceleration_deg_s2`; `read_rate_deg_s` is the controller's rate read-back; `hold` brings the axis to
    rest at its acceleration limit and holds it (the next move returns it to position mode). The serial
    driver has it where its profile has rate commands (`rotate`, `hold`, `rate`)."""

    def rotate_at(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None: ...
    def read_rate_deg_s(self, axis: int) -> float: ...
    def hold(self, axis: int) -> None: ...


# ---------------------------------------------------------------------- sensors and links


@runtime_checkable
class BlockCapturing(Protocol):
    """A DUT whose bridge captures a block by itself: one thread can start several and fetch them in rounds."""

    serial: str
    endpoint: str

    def post_capture(self, n_samples: int) -> bool: ...
    def begin_capture(self, n_samples: int, posted: bool = False) -> None: ...
    def capture_wait_s(self) -> float: ...
    def post_fetch(self) -> bool: ...
    def fetch_capture(self, posted: bool = False) -> bool: ...
    def end_capture(self) -> SampleBlock: ...


@runtime_checkable
class TemperaturePosting(Protocol):
    """A DUT whose temperature request can go out before its reply is read (every bridge asked at once)."""

    def begin_temperature_read(self) -> bool: ...
    def end_temperature_read(self) -> float | None: ...


@runtime_checkable
class Reconnecting(Protocol):
    """A device or link that can open its connection again after the link itself failed."""

    def reconnect(self) -> None: ...


@runtime_checkable
class RetriesExchanges(Protocol):
    """A driver that retries each of its wire exchanges itself, through the `call` it is given."""

    def retry_exchanges(self, call: RetryCall) -> None: ...


# ---------------------------------------------------------------------- asking a chamber


def controller_limits(chamber: Chamber) -> tuple[float, float] | None:
    """The controller's own set point limits; None from a driver that cannot read them."""
    return chamber.controller_limits_c() if isinstance(chamber, ControllerLimits) else None


def has_purge(chamber: Chamber) -> bool:
    """Whether the chamber's driver (and its profile) can switch a dry-air purge."""
    return isinstance(chamber, Purging)


def set_purge(chamber: Chamber, on: bool) -> None:
    if not isinstance(chamber, Purging):
        raise InstrumentError(f"chamber ({chamber.endpoint}): no dry-air purge output (its profile names none: "
                              "purge_on/purge_off in protocol_overrides, or registers.purge_register)")
    chamber.set_purge(on)


def humidity_pct(chamber: Chamber) -> float | None:
    """The controller's relative humidity reading; None where it has none."""
    return chamber.read_humidity_pct() if isinstance(chamber, HumiditySensing) else None


def setpoint_decimals(chamber: Chamber) -> int | None:
    """The decimals a chamber's set point is written with (a 16-bit register's, a template's `.1f`); None:
    written in full."""
    return chamber.setpoint_decimals if isinstance(chamber, SetpointResolution) else None


def alarm_active(chamber: Chamber) -> bool:
    """Whether the controller reports an alarm; False from one that cannot be asked."""
    return isinstance(chamber, AlarmReporting) and chamber.alarm_active()
