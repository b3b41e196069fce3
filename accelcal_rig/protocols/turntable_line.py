"""Turntable controller line protocols as data: command templates, reply patterns, terminators.

A profile says, for each operation, what to send (a template with `{axis}`, 1-based, and `{angle}`),
the pattern a good reply must match (named groups carry values), and — so that a simulator can speak
the same profile — the answer template a controller gives; a command without a reply pattern is sent and
not answered (SCPI settings). A status command that names `{axis}` is asked axis by axis, so a fault or a
busy axis is named. Any reply matching `error_pattern` is a controller error.

A move is complete when the controller says it is not busy, or — for controllers without such a query —
when every axis's rate has read below `at_rest_deg_s` for `at_rest_polls` polls in a row; either way the
engine then checks every angle against the rig's tolerance.

A rate table's profile also says how one axis turns at a constant rate (`rotate`: `{axis}`, `{rate}` in °/s,
`{acceleration}` in °/s², `{rate_limit}`, the rate's magnitude), how it is read back (`rate`) and how it is
brought to rest and held (`hold`); a profile without them (None) has no rate mode, and its driver no
constant-rate capability.

An ACL controller on TCP (and every interface but GPIB) answers every command with a response block, an error
code and a length before the text (`acknowledgement: length-prefixed`, protocols/acl_blocks.py); the driver
then reads a block after every command and takes a code other than 0 as a refusal.

A profile's `dialect` says how its controller reads a request (line_dialects.py): `plain`, the text as
written; `acl`, Acutronic's command language (acl_messages.py): templates in the manual's notation, sent
as lower-case long forms, read in any documented spelling and joined into lines by `;`.
"""

from __future__ import annotations

import re
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from accelcal_rig.protocols.line_dialects import check, request_pattern, spelled
from accelcal_rig.protocols.line_templates import NUMBER, TemplateCommand, regular_expression

#: What a request may name, with sample values: its axis (1-based) and angle; a rate command its rate,
#: acceleration limit and rate limit.
_SEND_SAMPLE: dict[str, object] = {"axis": 2, "angle": -45.0, "rate": -100.0, "acceleration": 50.0,
                                   "rate_limit": 100.0}
#: What an answer may name: the request's fields and the values replies carry.
_ANSWER_SAMPLE: dict[str, object] = {**_SEND_SAMPLE, "identity": "x", "busy": 0, "fault": 0, "rate": 0.0}


class Command(TemplateCommand):
    """`{axis}` (1-based) and `{angle:.5f}` style fields in a request; an answer also the values replies carry."""

    send_fields = _SEND_SAMPLE
    answer_fields = _ANSWER_SAMPLE

    @property
    def per_axis(self) -> bool:
        """Sent once for each axis (its template names `{axis}`)."""
        return "{axis" in self.send


class TurntableProtocol(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    dialect: Literal["plain", "acl"] = Field("plain", description="how the controller reads a request: the text "
                                            "as written, or Acutronic's ACL (headers in any documented spelling)")
    write_terminator: str = Field("\n", min_length=1, max_length=4)
    read_terminator: str = Field("\n", min_length=1, max_length=4)
    error_pattern: str = Field("^ERR", max_length=256)
    acknowledgement: Literal["none", "length-prefixed"] = Field(
        "none", description="ACL only: whether the controller answers every command with an error code and a length "
        "before the text (TM-8004-C §2: every interface but GPIB; protocols/acl_blocks.py), or answers queries "
        "only, with a line (GPIB, and this profile's serial line)")
    identify: Command
    move: Command
    position: Command
    busy: Command | None = None
    rate: Command | None = Field(None, description="an axis's rate (°/s): a move's completion where there is no "
                                 "busy query; a rate table's read-back")
    rotate: Command | None = Field(None, description="rate mode: turn {axis} at {rate} °/s, reached at "
                                   "{acceleration} °/s² (and {rate_limit}, the rate's magnitude, where the "
                                   "controller wants a limit); None: no rate mode")
    hold: Command | None = Field(None, description="rate mode: bring {axis} to rest at its acceleration limit "
                                 "and hold it there")
    stop: Command
    home: Command
    fault: Command
    setup: list[Command] = Field([], max_length=16, description="sent before the first move (interlock, mode), "
                                 "each once per axis if it names {axis}")
    setup_pause_s: float = Field(0.0, ge=0, le=5, description="wall-clock pause after each setup command: "
                                 "controllers that want time after a mode change")
    multi_axis_move: bool = Field(False, description="every axis's move in one line, joined by move_separator: "
                                  "the axes start together")
    move_separator: str = Field(";", min_length=1, max_length=4)
    busy_values: list[str] = Field(["1"], max_length=16, description="busy replies that mean moving")
    not_busy: str = Field("0", max_length=32, description="the busy reply of a table at rest (for simulators)")
    fault_ok: list[str] = Field(["0"], max_length=16, description="fault replies that mean no fault")
    fault_values: list[str] = Field([], max_length=16, description="if given, only these fault replies are "
                                    "faults (a controller whose healthy replies are not listed)")
    at_rest_deg_s: float = Field(0.01, gt=0, le=10, description="rate completion: below this an axis is at rest")
    at_rest_polls: int = Field(1, ge=1, le=100, description="rate completion: polls in a row at rest")

    _compiles = field_validator("error_pattern")(classmethod(lambda cls, value: regular_expression(value)))

    @model_validator(mode="after")
    def _completes(self) -> TurntableProtocol:
        if self.busy is None and self.rate is None:
            raise ValueError("a profile needs a busy query or a rate query to know a move is complete")
        for name, group in (("identify", "identity"), ("position", "angle"), ("busy", "busy"), ("rate", "rate"),
                            ("fault", "fault")):
            command = getattr(self, name)
            if command is not None and (command.reply is None or f"(?P<{group}>" not in command.reply):
                raise ValueError(f"{name}: the reply pattern must capture ({group})")
        if (self.rotate is None) != (self.hold is None):
            raise ValueError("rate mode needs both rotate and hold (or neither)")
        if self.rotate is not None:
            if self.rate is None:
                raise ValueError("rotate: a rate mode needs the rate query to read the rate back")
            for name in ("rotate", "hold"):
                if not getattr(self, name).per_axis:
                    raise ValueError(f"{name}: the request must name {{axis}} (rate mode turns one axis)")
            if "{rate" not in self.rotate.send.replace("{rate_limit", ""):
                raise ValueError("rotate: the request must name {rate}")
        if self.multi_axis_move and not self.move.per_axis:
            raise ValueError("multi_axis_move joins one move per axis: the move must name {axis}")
        if self.multi_axis_move and self.move.reply is not None:
            raise ValueError("multi_axis_move: the move must be unanswered (a controller answering each of the "
                             "joined commands would leave replies on the line)")
        if self.acknowledgement != "none" and self.dialect != "acl":
            raise ValueError("acknowledgement: length-prefixed acknowledgements are the ACL's (dialect: acl)")
        if self.dialect == "acl" and self.move_separator != ";":
            raise ValueError("move_separator: ACL joins commands in one line with ';'")
        for name, command in self.commands():
            if command.send != command.send.strip():
                raise ValueError(f"{name}: the request {command.send!r} has blanks at either end (lost on the line)")
            try:
                check(command.send, self.dialect)
            except ValueError as exc:
                raise ValueError(f"{name}: {exc}") from None
            if not request_pattern(command.send, self.dialect).fullmatch(self.request(command, **_SEND_SAMPLE)):
                raise ValueError(f"{name}: the request {command.send!r} does not read back as itself "
                                 "(no padding or blanks inside a field)")
        return self

    def commands(self) -> list[tuple[str, Command]]:
        """(name, command) of every operation the profile has, then its setup commands (`setup0`, …)."""
        names = ("identify", "move", "position", "busy", "rate", "rotate", "hold", "stop", "home", "fault")
        present = [(name, command) for name in names if (command := getattr(self, name)) is not None]
        return present + [(f"setup{i}", command) for i, command in enumerate(self.setup)]

    def request_pattern(self, command: Command) -> re.Pattern[str]:
        """Every request the controller reads as the command's (ACL: its commands from the root, joined by
        `;`, as acl_messages.commands gives a line)."""
        return request_pattern(command.send, self.dialect)

    def request(self, command: Command, **fields: object) -> str:
        """The request as the driver sends it: the template in the dialect's spelling, filled in."""
        return spelled(command.send, self.dialect).format(**fields)


#: The built-in profile: a plain SCPI-like line protocol, one command per line, one reply per command.
ACCELCAL_LINE = TurntableProtocol(
    identify=Command(send="*IDN?", reply=r"(?P<identity>.+)", answer="{identity}"),
    move=Command(send="MOV {axis} {angle:.5f}", reply="OK", answer="OK"),
    position=Command(send="POS? {axis}", reply=r"(?P<angle>[-+]?\d+(\.\d*)?([eE][-+]?\d+)?)", answer="{angle:.6f}"),
    busy=Command(send="BUSY?", reply=r"(?P<busy>[01])", answer="{busy}"),
    rate=Command(send="RATE? {axis}", reply=r"(?P<rate>[-+]?\d+(\.\d*)?([eE][-+]?\d+)?)", answer="{rate:.6f}"),
    rotate=Command(send="RATE {axis} {rate:.5f} {acceleration:.5f}", reply="OK", answer="OK"),
    hold=Command(send="HOLD {axis}", reply="OK", answer="OK"),
    stop=Command(send="STOP", reply="OK", answer="OK"),
    home=Command(send="HOME", reply="OK", answer="OK"),
    fault=Command(send="FAULT?", reply=r"(?P<fault>\d+)", answer="{fault}"),
)

_N = NUMBER
#: Acutronic ACUTROL3000 (ACL, SCPI-like; facts and sources in docs/instruments.md): position demanded per
#: axis, all axes in one compound line; no in-position query, so a move is complete when every axis's rate
#: has read zero for three polls; a tripped interlock reads "Fault". Rate mode (TM-8004-C §4.3.6, 4.6.2,
#: 4.6.8, 4.7.5, 4.10.5): the rate mode's rate and acceleration limits, the rate demand, then rate mode; a
#: hold demands zero rate, to which the axis decelerates at that acceleration limit and stays (in rate mode:
#: the next move sets position mode up again). Headers in the manual's notation, each short form the
#: shortest its examples show (`:D:P`, `:R:P?`, `:R:A 2;R 2`, `:I:C 1`, `:M:P 2`, `:L:R`, `:LIM:ACC`, where
#: `:L:A` would also be Limit:Absolute); sent as lower-case long forms, as both public clients spell them.
ACUTROL3000 = TurntableProtocol(
    dialect="acl",
    identify=Command(send="*IDN?", reply=r"(?P<identity>.+)", answer="{identity}"),
    move=Command(send=":Demand:Position {axis},{angle:.5f}"),
    multi_axis_move=True, move_separator=";",
    position=Command(send=":Read:Position? {axis}", reply=rf"(?P<angle>{_N})", answer="{angle:.5f}"),
    rate=Command(send=":Read:Rate? {axis}", reply=rf"(?P<rate>{_N})", answer="{rate:.5f}"),
    at_rest_deg_s=0.01, at_rest_polls=3,
    rotate=Command(send=":Limit:Rate R,{axis},{rate_limit:.5f};:Limit:ACCeleration R,{axis},{acceleration:.5f};"
                   ":Demand:Rate {axis},{rate:.5f};:Mode:Rate {axis}"),
    hold=Command(send=":Demand:Rate {axis},0"),
    stop=Command(send=":Demand:Rate {axis},0;:Mode:Rate {axis};:Demand:Rate {axis},0"),
    home=Command(send=":Demand:Position {axis},0"),
    fault=Command(send=":INTerlock? {axis}", reply=r"(?P<fault>\w+)", answer="{fault}"),
    fault_values=["Fault", "Open"],  # tripped, or opened since the setup closed it
    setup=[Command(send=":Interlock:Close {axis}"), Command(send=":Mode:Position {axis}")],
    setup_pause_s=0.3,
)

PROTOCOLS: dict[str, TurntableProtocol] = {"accelcal-line": ACCELCAL_LINE, "acutrol3000": ACUTROL3000}


def turntable_protocol(name: str, overrides: dict[str, object] | None = None) -> TurntableProtocol:
    """A built-in profile with any fields the rig config overrides (validated)."""
    merged = {**PROTOCOLS[name].model_dump(), **(overrides or {})}
    return TurntableProtocol.model_validate(merged)
