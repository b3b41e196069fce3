"""What a simulated line controller answers beyond its profile's operations, the base each dialect's extras
build on (sim/line_extras.py picks them): the requests the makers' libraries and other public clients send
that the rig's driver does not, and the values the profile's own answers take from the controller's state.
Methods are called with the lab's lock held."""

from __future__ import annotations

from typing import Protocol

from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol, Operation
from accelcal_rig.sim.lab import VirtualLab


class Panel(Protocol):
    """The simulated controller's own state beyond the lab's (tests set it), and its set point writer."""

    local_mode: bool
    alarms: int
    warnings: int
    identity: str
    #: The chamber's own range: no controller limit may be set beyond it (the limits it starts with).
    rated_limits_c: tuple[float, float]
    #: The set point last written over the wire (what TEMP? shows), None before the first.
    last_setpoint_c: float | None

    def write_setpoint(self, now: float, setpoint_c: float) -> None:
        """Take a set point as the profile's own write does (clamped to the limits, a stalled chamber's kept)."""


class Unknown:
    """A request the controller family does not know: answered with the profile's unknown-command answer."""


UNKNOWN = Unknown()


class Unsupported:
    """A request the controller family has that the simulated controller does not model: answered with the
    profile's `unsupported_answer` (the instrument's own 'not supported'), else as an unknown one."""


UNSUPPORTED = Unsupported()

#: What an extra answers: a reply, None (no reply), or one of the two answers the profile gives.
Answer = str | None | Unknown | Unsupported


class Extras:
    """plain: nothing beyond the profile."""

    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        self._protocol, self._lab, self._panel = protocol, lab, panel

    def values(self) -> dict[str, object]:
        """Fields the profile's answers take from the state, beyond the generic ones."""
        return {}

    def carried_out(self, operation: Operation) -> None:
        """A profile operation was carried out (a write)."""

    def answer(self, request: str) -> Answer:
        return UNKNOWN
