"""What a simulated ACUTROL3000 carries out beyond its profile's operations (TM-8004-C): the commands the
public clients send that the simulated table can hold, from its motion. Each command is in the manual's
notation with the section it follows; acl_equivalents.py first rewrites `ALL` axes and the one-command mode
form to these.

- `:Mode? <axis>` answers the axis's mode letter: `P` position, `R` rate (the manual's example `P;R;P`),
  `O` off [inferred: the manual shows only `P` and `R`]; an axis is Off until a mode command reaches it.
  Modes follow every `:Mode:Position`, `:Mode:Rate` and `:Mode:Off` carried out, the profile's own too.
- `:Mode:Off <axis>`: closed-loop zero velocity, "a smooth controlled stop … equivalent to Rate Mode with
  a demand of 0" (§4.7.3): the axis decelerates at its acceleration limit and holds; a move then needs
  position mode again.
- `:Mode:Rate <axis>` (§4.7.5) and `:Demand:Rate <axis>,<rate>` (§4.3.6): in rate mode the axis goes to its
  rate demand "as quickly as possible, without any overshoot, given ... programmed limits": at Rate mode's
  acceleration limit, the demand held to Rate mode's rate limit (acl_limits.py). A rate demand outside
  rate mode is kept for when the axis enters it; an axis whose interlock is open does not move.
- `:Demand:Deltaposition <axis>,<data>` (§4.3.2): the position demand changed by `data` "and the result
  re-commanded as the new position" (a move, as the profile's: only in position mode); its query answers
  the last step received.
- `:Read:Acceleration? <axis>` (§4.10.1; `?` optional, §4.10): the axis's acceleration (its rate ramp's,
  TurntableMotion.acceleration_deg_s2), NR2 as the other reads.
- `:Limit:Rate[?] <mode>,<axis>[,<limit>]`, `:Limit:ACCeleration[?] <mode>,<axis>[,<limit>]` (§4.6.2,
  4.6.8): per mode and axis, held in acl_limits.py; the mode as §4.6 / §2.7 read it.
- `:Interlock:Open <axis>` (§4.5.5: "the specified axis is to be shut down in an orderly fashion"): the axis
  comes to rest (TurntableMotion.halt), leaves its mode's motion and reads `Open` at `:INTerlock?` (a fault
  value of the profile, so `*STB?` reads 65) until `:Interlock:Close` servos it again. A tripped interlock
  (`Fault`, fault injection) is frozen: closing does not clear it; `:Interlock:Reset` (§4.5.6: "unfreeze the
  status on all axes that are faulted ... and axes can be servoed") turns every `Fault` into `Open`. The
  manual's Reset takes no argument; Acutronic's own TCP client sends `:interlock:reset 1` and expects `OK`
  (AcutronicRobotics/acutrol ac117.json): an axis after it is read, checked and otherwise ignored [inferred].
- `:Utility:Lockout {ON|OFF}` and its query (§4.14.2, `OFF` at power-up as the example reads): held; the
  simulator has no front panel to lock out.
- `:Utility:Format FLOat` and `:Utility:Format?` (§4.14.1): answers are NR2 already; `BINary` (32-bit
  binary answers) is not simulated and refused.
- `*STB?`: bit 0 the system interlock summary with bit 6 (MSS) — `65` while an axis's interlock reads a
  fault, else `0` (§3.10).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Protocol

from accelcal_rig.protocols import acl_arguments
from accelcal_rig.protocols.acl_messages import request_pattern
from accelcal_rig.protocols.line_templates import finite_number
from accelcal_rig.sim.acl_limits import ModeLimits, acceleration_limit_valid, rate_limit_valid
from accelcal_rig.sim.lab import VirtualLab

#: `:INTerlock?` of an axis shut down by `:Interlock:Open`, and of a tripped one (the profile's fault values).
OPENED, TRIPPED = "Open", "Fault"
#: The mode each mode command sets, by its header in the manual's notation (§4.7.3–4.7.5).
_MODES = {":Mode:Position {axis}": "P", ":Mode:Rate {axis}": "R", ":Mode:Off {axis}": "O"}
_CLOSE = re.compile(request_pattern(":Interlock:Close {axis}"))


class ServoTable(Protocol):
    """What the simulated controller does to the table for the extras (sim/turntable_server.py)."""

    faults: list[str]

    def servo_move(self, axis: int, angle_deg: float) -> None:
        """A position demand, as the profile's move: an axis out of position mode stays."""

    def servo_turn(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        """Rate mode: the axis goes to `rate_deg_s` at `acceleration_deg_s2` (a position move then needs the setup)."""

    def leave_position_mode(self, axis: int) -> None:
        """A move needs the profile's setup again."""

    def servo_shut_down(self, axis: int) -> None:
        """The axis brought to rest where it is and out of servo: a move or a rate needs the setup again."""


Handler = Callable[["AclExtras", dict[str, str], int], "str | None"]


class AclExtras:
    """Called with the lab's lock held, command by command, each from the root (acl_messages.commands)."""

    def __init__(self, lab: VirtualLab, table: ServoTable, fault_values: list[str], healthy: str) -> None:
        self._lab = lab
        self._table = table
        self._fault_values = fault_values
        self._healthy = healthy
        n_axes = len(lab.motion.speeds_deg_s)
        self.modes = ["O"] * n_axes
        self.rate_demands = [0.0] * n_axes
        self.deltas = [0.0] * n_axes
        self.lockout = "OFF"
        self.limits = ModeLimits([float(s) for s in lab.motion.speeds_deg_s], lab.max_rates_deg_s,
                                 lab.rate_acceleration_deg_s2)
        self._mode_commands = [(re.compile(request_pattern(template)), mode) for template, mode in _MODES.items()]
        self._commands = [(re.compile(request_pattern(template)), handler) for template, handler in _COMMANDS]

    def recognise(self, command: str) -> dict[str, str] | None:
        """The fields of a command the extras serve (an empty dict for one with none); None: not theirs, or an
        enumerated argument the controller does not read (§2.7)."""
        for pattern, handler in self._commands:
            match = pattern.fullmatch(command)
            if match is not None:
                fields = match.groupdict()
                return fields if _arguments_read(fields) and _limit_taken(handler, fields) else None
        return None

    def answer(self, command: str, axis: int | None) -> str | None:
        """Carry out a command recognise() took (`axis` 0-based, checked); its answer, None if unanswered."""
        for pattern, handler in self._commands:
            match = pattern.fullmatch(command)
            if match is not None:
                return handler(self, match.groupdict(), -1 if axis is None else axis)
        raise ValueError(f"not an extra: {command!r}")

    def observe(self, command: str, axis: int | None) -> None:
        """A command was carried out (the profile's too): a mode command sets its axis's mode, a rate demand
        and a limit are kept, a close servos an opened interlock."""
        if axis is None:
            return
        for pattern, mode in self._mode_commands:
            if pattern.fullmatch(command):
                self.modes[axis] = mode
        for pattern, keep in _KEPT:
            match = pattern.fullmatch(command)
            if match is not None:
                keep(self, match.groupdict(), axis)
        if _CLOSE.fullmatch(command) and self._table.faults[axis] == OPENED:
            self._table.faults[axis] = self._healthy

    # ------------------------------------------------------------------ what each command does
    def _mode(self, fields: dict[str, str], axis: int) -> str:
        return self.modes[axis]

    def _off(self, fields: dict[str, str], axis: int) -> None:
        self._lab.motion.hold(self._lab.clock.now(), axis)
        self._table.leave_position_mode(axis)

    def _rate_mode(self, fields: dict[str, str], axis: int) -> None:
        self.modes[axis] = "R"
        self._turn(axis)

    def _rate_demand(self, fields: dict[str, str], axis: int) -> None:
        self.rate_demands[axis] = finite_number(fields["rate"])
        if self.modes[axis] == "R":
            self._turn(axis)

    def _turn(self, axis: int) -> None:
        if self._table.faults[axis] in self._fault_values:
            return  # an open interlock: the axis is not servoed
        limit = self.limits.rate("Rate", axis)
        rate = max(-limit, min(limit, self.rate_demands[axis]))
        self._table.servo_turn(axis, rate, self.limits.acceleration("Rate", axis))

    def _delta(self, fields: dict[str, str], axis: int) -> None:
        step = finite_number(fields["delta"])
        motion = self._lab.motion
        demand = float(motion.last_command_deg[axis])
        if demand != demand:  # never commanded: the demand is where the axis stands
            demand = float(motion.position_deg(self._lab.clock.now())[axis])
        self.deltas[axis] = step
        self._table.servo_move(axis, demand + step)

    def _delta_query(self, fields: dict[str, str], axis: int) -> str:
        return f"{self.deltas[axis]:.5f}"

    def _acceleration(self, fields: dict[str, str], axis: int) -> str:
        return f"{self._lab.motion.acceleration_deg_s2(self._lab.clock.now(), axis):.5f}"

    def _rate_limit(self, fields: dict[str, str], axis: int) -> str:
        return f"{self.limits.rate(_limit_mode(fields), axis):.5f}"

    def _acceleration_limit(self, fields: dict[str, str], axis: int) -> str:
        return f"{self.limits.acceleration(_limit_mode(fields), axis):.5f}"

    def _open(self, fields: dict[str, str], axis: int) -> None:
        if self._table.faults[axis] != TRIPPED:
            self._table.faults[axis] = OPENED
        self._table.servo_shut_down(axis)

    def _reset(self, fields: dict[str, str], axis: int) -> None:
        faults = self._table.faults
        faults[:] = [OPENED if fault == TRIPPED else fault for fault in faults]

    def _set_lockout(self, fields: dict[str, str], axis: int) -> None:
        self.lockout = str(acl_arguments.enumerated(fields["state"], acl_arguments.SWITCH))

    def _lockout(self, fields: dict[str, str], axis: int) -> str:
        return self.lockout

    def _set_format(self, fields: dict[str, str], axis: int) -> None:
        """FLOat only (recognise refuses BINary): the answers are NR2 already."""

    def _format(self, fields: dict[str, str], axis: int) -> str:
        return "FLOAT"

    def _status_byte(self, fields: dict[str, str], axis: int) -> str:
        return "65" if any(fault in self._fault_values for fault in self._table.faults) else "0"

    # the limits a command writes (kept also when the profile's rotate writes them)
    def _keep_rate_limit(self, fields: dict[str, str], axis: int) -> None:
        self.limits.set_rate(_limit_mode(fields), axis, finite_number(fields["limit"]))

    def _keep_acceleration_limit(self, fields: dict[str, str], axis: int) -> None:
        self.limits.set_acceleration(_limit_mode(fields), axis, finite_number(fields["limit"]))

    def _keep_rate_demand(self, fields: dict[str, str], axis: int) -> None:
        self.rate_demands[axis] = finite_number(fields["rate"])


def _limit_mode(fields: dict[str, str]) -> str:
    return str(acl_arguments.limit_mode(fields["mode"]))


def _arguments_read(fields: dict[str, str]) -> bool:
    """Whether the command's enumerated arguments name a value the controller (and the simulator) takes."""
    if "mode" in fields and acl_arguments.limit_mode(fields["mode"]) is None:
        return False
    if "state" in fields and acl_arguments.enumerated(fields["state"], acl_arguments.SWITCH) is None:
        return False
    return "format" not in fields or acl_arguments.enumerated(fields["format"], acl_arguments.FORMATS) == "FLOat"


def _rate_limit_written(extras: AclExtras, fields: dict[str, str], axis: int) -> None:
    """Kept by observe(), as the profile's rotate writes it."""


def _acceleration_limit_written(extras: AclExtras, fields: dict[str, str], axis: int) -> None:
    """Kept by observe(), as the profile's rotate writes it."""


def _limit_taken(handler: Handler, fields: dict[str, str]) -> bool:
    """A limit written within what a controller takes (acl_limits.py); a number it cannot read is refused by
    the server's own check of every number."""
    if "limit" not in fields:
        return True
    try:
        value = finite_number(fields["limit"])
    except ValueError:
        return True
    return acceleration_limit_valid(value) if handler is _acceleration_limit_written else rate_limit_valid(value)


#: Each command the extras carry out (the manual's notation; sections above) and what it does.
_COMMANDS: tuple[tuple[str, Handler], ...] = (
    (":Mode? {axis}", AclExtras._mode),
    (":Mode:Off {axis}", AclExtras._off),
    (":Mode:Rate {axis}", AclExtras._rate_mode),
    (":Demand:Rate {axis},{rate}", AclExtras._rate_demand),
    (":Demand:Deltaposition {axis},{delta}", AclExtras._delta),
    (":Demand:Deltaposition? {axis}", AclExtras._delta_query),
    (":Read:Acceleration? {axis}", AclExtras._acceleration),
    (":Limit:Rate {mode},{axis},{limit}", _rate_limit_written),
    (":Limit:Rate? {mode},{axis}", AclExtras._rate_limit),
    (":Limit:ACCeleration {mode},{axis},{limit}", _acceleration_limit_written),
    (":Limit:ACCeleration? {mode},{axis}", AclExtras._acceleration_limit),
    (":Interlock:Open {axis}", AclExtras._open),
    (":Interlock:Reset", AclExtras._reset),
    (":Interlock:Reset {axis}", AclExtras._reset),  # the maker's own TCP client names an axis (below)
    (":Utility:Lockout {state}", AclExtras._set_lockout),
    (":Utility:Lockout?", AclExtras._lockout),
    (":Utility:Format {format}", AclExtras._set_format),
    (":Utility:Format?", AclExtras._format),
    ("*STB?", AclExtras._status_byte),
)

#: What observe() keeps of a command carried out, whoever carried it out (the profile's rotate writes limits
#: and a rate demand in one line).
_KEPT = tuple((re.compile(request_pattern(template)), keep) for template, keep in (
    (":Limit:Rate {mode},{axis},{limit}", AclExtras._keep_rate_limit),
    (":Limit:ACCeleration {mode},{axis},{limit}", AclExtras._keep_acceleration_limit),
    (":Demand:Rate {axis},{rate}", AclExtras._keep_rate_demand),
))
