"""A simulated turntable controller on a pseudo-terminal, speaking a line-protocol profile: each request is
recognised by its command's template in every spelling the profile's dialect takes and answered with the
command's answer, from the lab's turntable motion at the shared clock's time. An ACL controller reads a line
as commands joined by `;` (acl_messages.py): each run of them that is one of the profile's operations is
carried out, as are the ACL commands beyond the profile that the simulated table can hold
(sim/turntable_acl.py; `ALL` axes and the one-command mode form rewritten first, sim/acl_equivalents.py), and
the queries' answers come back joined by `;`; a line with any command it does not know, or any it cannot
carry out, is refused whole and nothing moves."""

from __future__ import annotations

import re

from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.protocols import acl_blocks, acl_messages
from accelcal_rig.protocols.line_dialects import request_pattern
from accelcal_rig.protocols.line_templates import finite_number
from accelcal_rig.protocols.turntable_line import Command, TurntableProtocol
from accelcal_rig.sim.acl_equivalents import rewritten
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.line_answers import MAX_LINE_BYTES
from accelcal_rig.sim.pty_line_server import PtyLineServer
from accelcal_rig.sim.turntable_acl import AclExtras

#: Operations that move the table (the last of them is kept for tests).
_MOTION = ("move", "stop", "home", "rotate", "hold")
#: The fields of a request that carry a number (degrees, °/s, °/s²; an ACL extra's step and limit).
_NUMBER_FIELDS = ("angle", "rate", "acceleration", "rate_limit", "delta", "limit")


class SimulatedTurntableServer:
    def __init__(self, lab: VirtualLab, protocol: TurntableProtocol, identity: str = "accelcal-rig simulated turntable",
                 faults: ReplyFaults | None = None, stall_after_s: float | None = None):
        self._lab = lab
        self._stall_after_s = stall_after_s
        #: The last motion command (move, stop, home) as received, for tests that check the safe state.
        self.last_command: str | None = None
        self._protocol = protocol
        self._identity = identity
        self._patterns = [(name, command, request_pattern(command.send, protocol.dialect))
                          for name, command in protocol.commands()]
        #: An ACL message's operations, most commands first (a stop's first command is also a hold).
        self._by_length = sorted(((command.send.count(acl_messages.SEPARATOR) + 1, name, command, pattern)
                                  for name, command, pattern in self._patterns), key=lambda step: -step[0])
        if protocol.write_terminator != protocol.read_terminator:
            raise ValueError("the simulated turntable needs one terminator for both directions")
        if protocol.acknowledgement == "length-prefixed":  # every command answered with a block (acl_blocks.py)
            self._server = PtyLineServer(lambda request: _acknowledged(self._handle(request)),
                                         protocol.write_terminator.encode(), "simulated-turntable", faults,
                                         reply_terminator=b"", encoding="latin-1",
                                         overlong=lambda head: _acknowledged(_overlong_answer(head)))
        else:
            self._server = PtyLineServer(self._handle, protocol.write_terminator.encode(), "simulated-turntable",
                                         faults, overlong=_overlong_answer)
        self.path = self.endpoint = self._server.path
        n_axes = len(lab.motion.speeds_deg_s)
        #: Fault reply of each axis (fault injection sets them); a profile without per-axis faults reads axis 1's.
        self.faults = [protocol.fault_ok[0]] * n_axes
        #: Axes whose setup (interlock, mode) has been received since the last stop; a profile with setup
        #: ignores moves before it, as a table out of position mode does.
        self._set_up = [not protocol.setup] * n_axes
        self._setup_seen: list[set[str]] = [set() for _ in range(n_axes)]
        #: Axes a rate command has put in rate mode (a profile with setup then ignores moves until it again).
        self._rate_mode = [False] * n_axes
        self.acl = AclExtras(lab, self, protocol.fault_values, protocol.fault_ok[0])

    @property
    def fault(self) -> str:
        return self.faults[0]

    @fault.setter
    def fault(self, value: str) -> None:
        self.faults = [value] * len(self.faults)

    @property
    def buffered_bytes(self) -> int:
        """Bytes held of requests not yet ended (bounded: sim/line_answers.py), for tests."""
        return self._server.buffered_bytes

    @property
    def peak_buffered_bytes(self) -> int:
        """The most bytes ever held of an unended request between two reads, for tests."""
        return self._server.peak_buffered_bytes

    def start(self) -> SimulatedTurntableServer:
        self._server.start()
        return self

    def stop(self) -> None:
        self._server.stop()

    def _handle(self, request: str) -> str | None:
        protocol = self._protocol
        if protocol.dialect == "acl":
            return self._handle_message(request)
        if protocol.multi_axis_move and protocol.move_separator in request:  # every axis's move in one line
            pattern = protocol.move.request_pattern()
            matches = [pattern.fullmatch(part) for part in request.split(protocol.move_separator)]
            if all(matches):
                moves = [m.groupdict() for m in matches if m is not None]
                try:  # every part read before any moves: a bad one moves nothing
                    n_axes = len(self._lab.motion.speeds_deg_s)
                    for fields in moves:
                        if not 1 <= _axis_number(fields["axis"]) <= n_axes:
                            raise ValueError(f"no axis {fields['axis']}")
                        _numbers(fields)
                except (ValueError, KeyError) as exc:
                    return f"ERR {exc}"
                for fields in moves:
                    self._answer("move", "", fields)
                self.last_command = request
                return protocol.move.answer
        matched, answer = self._match(request)
        return answer if matched else f"ERR unknown command {request!r}"

    def _handle_message(self, request: str) -> str | None:
        """An ACL line: every command recognised and every value read before any is carried out."""
        commands = rewritten(acl_messages.commands(request), len(self._lab.motion.speeds_deg_s))
        steps: list[tuple[str, Command | None, dict[str, str], str]] = []
        taken = 0
        while taken < len(commands):
            step = self._recognise(commands[taken:])
            if step is None:
                return f"ERR unknown command {request!r}"
            steps.append(step)
            taken += step[3].count(acl_messages.SEPARATOR) + 1
        n_axes = len(self._lab.motion.speeds_deg_s)
        try:
            for _, _, fields, _ in steps:
                _numbers(fields)
                if "axis" in fields and not 1 <= _axis_number(fields["axis"]) <= n_axes:
                    raise ValueError(f"no axis {fields['axis']}")
        except ValueError as exc:
            return f"ERR {exc}"
        answers = []
        for name, command, fields, text in steps:
            axis = _axis_number(fields["axis"]) - 1 if "axis" in fields else None
            if command is None:
                with self._lab.lock:
                    answer = self.acl.answer(text, axis)
            else:
                answer = self._answer(name, command.answer or "", fields)
                answer = None if command.answer is None else answer
            for part in text.split(acl_messages.SEPARATOR):
                self.acl.observe(part, axis)
            if answer is not None:
                answers.append(answer)
        if any(name in _MOTION for name, *_ in steps):
            self.last_command = request
        return acl_messages.SEPARATOR.join(answers) if answers else None

    def _recognise(self, commands: list[str]) -> tuple[str, Command | None, dict[str, str], str] | None:
        """The operation (or ACL extra: no command) the first of `commands` begin: (name, command, fields,
        its commands joined)."""
        for count, name, command, pattern in self._by_length:
            text = acl_messages.SEPARATOR.join(commands[:count])
            match = pattern.fullmatch(text) if count <= len(commands) else None
            if match is not None:
                return name, command, match.groupdict(), text
        fields = self.acl.recognise(commands[0])
        return None if fields is None else ("acl", None, fields, commands[0])

    # ------------------------------------------------------------------ the ACL extras' table (ServoTable)
    def leave_position_mode(self, axis: int) -> None:
        """Off mode (an ACL extra): a move needs the profile's setup again."""
        if self._protocol.setup:
            self._set_up[axis], self._setup_seen[axis] = False, set()

    def servo_move(self, axis: int, angle_deg: float) -> None:
        """A position demand as the profile's move carries it out (the lab's lock held)."""
        now = self._lab.clock.now()
        if not self._stalled(now) and self._set_up[axis]:
            self._lab.motion.command_axis(now, axis, angle_deg)

    def servo_turn(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        """Rate mode as the profile's rotate carries it out (the lab's lock held)."""
        now = self._lab.clock.now()
        if self._stalled(now):
            return
        self._lab.motion.rotate(now, axis, rate_deg_s, acceleration_deg_s2)
        self._rate_mode[axis] = True
        self.leave_position_mode(axis)

    def servo_shut_down(self, axis: int) -> None:
        """An opened interlock: the axis at rest where it is, out of both modes (the lab's lock held)."""
        self._lab.motion.halt(self._lab.clock.now(), axis)
        self._rate_mode[axis] = False
        self.leave_position_mode(axis)

    def _stalled(self, now: float) -> bool:
        return self._stall_after_s is not None and now >= self._stall_after_s

    def _match(self, request: str) -> tuple[bool, str | None]:
        """(whether one command's template matches the request, its answer: None if it is unanswered)."""
        for name, command, pattern in self._patterns:
            match = pattern.fullmatch(request)
            if match is not None:
                try:  # a refused request (no such axis, a number it cannot read) moves nothing
                    answer = self._answer(name, command.answer or "", match.groupdict())
                except (ValueError, IndexError) as exc:
                    return True, f"ERR {exc}"
                if name in _MOTION:
                    self.last_command = request
                return True, None if command.answer is None else answer
        return False, None

    def _answer(self, name: str, template: str, fields: dict[str, str]) -> str:
        numbers = _numbers(fields)  # every number read before anything moves
        lab, motion = self._lab, self._lab.motion
        with lab.lock:
            now = lab.clock.now()
            n_axes = len(motion.speeds_deg_s)
            axis = _axis_number(fields["axis"]) - 1 if "axis" in fields else None
            if axis is not None and not 0 <= axis < n_axes:
                raise ValueError(f"no axis {axis + 1}")
            axes = range(n_axes) if axis is None else (axis,)
            stalled = self._stalled(now)
            if name.startswith("setup"):
                for a in axes:
                    self._setup_seen[a].add(name)
                    self._set_up[a] = len(self._setup_seen[a]) == len(self._protocol.setup)
                    self._rate_mode[a] = self._rate_mode[a] and not self._set_up[a]
            elif name == "move" and not stalled and axis is not None and self._set_up[axis]:
                motion.command_axis(now, axis, numbers["angle"])  # a stalled or unarmed table stays put
            elif name == "rotate" and not stalled and axis is not None and (self._set_up[axis] or self._rate_mode[axis]):
                motion.rotate(now, axis, numbers["rate"], numbers["acceleration"]
                              if "acceleration" in numbers else self._lab.rate_acceleration_deg_s2[axis])
                self._rate_mode[axis] = True
                if self._protocol.setup:  # out of position mode: a move needs the setup again
                    self._set_up[axis], self._setup_seen[axis] = False, set()
            elif name == "hold" and axis is not None:
                motion.hold(now, axis)
            elif name == "stop":
                motion.stop(now)
                for a in axes if self._protocol.setup else ():  # a stop leaves the mode a move needs
                    self._set_up[a], self._setup_seen[a] = False, set()
            elif name == "home":
                target = motion.position_deg(now)
                target[list(axes)] = 0.0
                motion.command(now, target)
            shown = 0 if axis is None else axis
            values = {
                "identity": self._identity,
                "angle": float(motion.position_deg(now)[shown]),
                "busy": self._protocol.not_busy if motion.in_position(now, axis) else self._protocol.busy_values[0],
                "rate": motion.read_rate_deg_s(now, shown),
                "fault": self.faults[shown],
            }
        return template.format(**values)


def _axis_number(text: str) -> int:
    """An axis as a controller reads one: ASCII digits only (int() would also take `+1`, `1_0` or other
    scripts' digits)."""
    if not re.fullmatch(r"[0-9]{1,3}", text):
        raise ValueError(f"no axis {text}")
    return int(text)


def _numbers(fields: dict[str, str]) -> dict[str, float]:
    """The request's numbers, each finite and written as a controller writes one: ValueError (answered `ERR …`)
    for `nan`, `inf`, `1e400` and the like, which would otherwise reach the simulated motion."""
    return {name: finite_number(fields[name]) for name in _NUMBER_FIELDS if name in fields}


def _acknowledged(answer: str | None) -> str:
    """A command's answer as a response block (sent as latin-1, byte for byte): a refusal's code is the
    simulator's for an unknown command, a setting's text "OK" (as AcutronicRobotics' TCP client reads it)."""
    refused = answer is not None and answer.startswith("ERR")
    text = "OK" if answer is None else answer
    return acl_blocks.block(acl_blocks.UNKNOWN_COMMAND if refused else 0, text).decode("latin-1")


def _overlong_answer(head: str) -> str:
    """A line longer than any request is answered as an unknown command (every profile's simulator answers
    those `ERR …`)."""
    return f"ERR unknown command {ascii(head)}... (a line over {MAX_LINE_BYTES} bytes)"  # ASCII, as its replies


def serve_line(lab: VirtualLab, config: TurntableConfig, faults: InstrumentFaults) -> SimulatedTurntableServer:
    """The serial turntable driver's simulator: a controller speaking the config's line protocol."""
    return SimulatedTurntableServer(lab, config.line_protocol(), faults=faults.replies,
                                    stall_after_s=faults.after_s(faults.settings.turntable_stall_after_min))
