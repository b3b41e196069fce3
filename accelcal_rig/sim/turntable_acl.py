"""What a simulated ACUTROL3000 answers beyond its profile's operations (TM-8004-C): the queries the public
clients send that the simulated table can answer, and Off mode, which both clients command.

- `:Mode? <axis>` answers the axis's mode letter: `P` position, `R` rate (the manual's example `P;R;P`),
  `O` off [inferred: the manual shows only `P` and `R`]; an axis is Off until a mode command reaches it.
  Modes follow every `:Mode:Position`, `:Mode:Rate` and `:Mode:Off` carried out, the profile's own too.
- `:Mode:Off <axis>`: closed-loop zero velocity, "a smooth controlled stop … equivalent to Rate Mode with
  a demand of 0" (§4.7.3): the axis decelerates at its acceleration limit and holds; a move then needs
  position mode again.
- `*STB?`: bit 0 the system interlock summary with bit 6 (MSS) — `65` while an axis's interlock reads a
  fault, else `0` (§3.10).
"""

from __future__ import annotations

import re
from collections.abc import Callable

from accelcal_rig.protocols.acl_messages import request_pattern
from accelcal_rig.sim.lab import VirtualLab

#: The mode each mode command sets, by its header in the manual's notation (§4.7.3–4.7.5).
_MODES = {":Mode:Position {axis}": "P", ":Mode:Rate {axis}": "R", ":Mode:Off {axis}": "O"}
_MODE_QUERY = re.compile(request_pattern(":Mode? {axis}"))
_OFF = re.compile(request_pattern(":Mode:Off {axis}"))
_STATUS_BYTE = re.compile(request_pattern("*STB?"))


class AclExtras:
    """Called with the lab's lock held, command by command, each from the root (acl_messages.commands)."""

    def __init__(self, lab: VirtualLab, n_axes: int, tripped: Callable[[], bool],
                 leave_position_mode: Callable[[int], None]) -> None:
        self._lab = lab
        self._tripped = tripped
        self._leave_position_mode = leave_position_mode
        self.modes = ["O"] * n_axes
        self._mode_commands = [(re.compile(request_pattern(template)), mode) for template, mode in _MODES.items()]

    def recognise(self, command: str) -> dict[str, str] | None:
        """The fields of a command the extras serve (an empty dict for one with none); None: not theirs."""
        for pattern in (_MODE_QUERY, _OFF, _STATUS_BYTE):
            match = pattern.fullmatch(command)
            if match is not None:
                return match.groupdict()
        return None

    def answer(self, command: str, axis: int | None) -> str | None:
        """Carry out a command recognise() took (`axis` 0-based, checked); its answer, None if unanswered."""
        if _MODE_QUERY.fullmatch(command):
            assert axis is not None
            return self.modes[axis]
        if _OFF.fullmatch(command):
            assert axis is not None
            self._lab.motion.hold(self._lab.clock.now(), axis)
            self._leave_position_mode(axis)
            return None
        return "65" if self._tripped() else "0"

    def observe(self, command: str, axis: int | None) -> None:
        """A command was carried out: a mode command sets its axis's mode."""
        for pattern, mode in self._mode_commands:
            if axis is not None and pattern.fullmatch(command):
                self.modes[axis] = mode
