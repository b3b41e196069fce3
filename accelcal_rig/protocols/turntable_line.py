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
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from accelcal_rig.protocols.line_templates import NUMBER, TemplateCommand, regular_expression, round_trips

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

    write_terminator: str = Field("\n", min_length=1, max_length=4)
    read_terminator: str = Field("\n", min_length=1, max_length=4)
    error_pattern: str = Field("^ERR", max_length=256)
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
        for name in ("identify", "move", "position", "busy", "rate", "rotate", "hold", "stop", "home", "fault"):
            command = getattr(self, name)
            if command is not None and command.send != command.send.strip():
                raise ValueError(f"{name}: the request {command.send!r} has blanks at either end (lost on the line)")
            if command is not None and not round_trips(command.send, _SEND_SAMPLE):
                raise ValueError(f"{name}: the request {command.send!r} does not read back as itself "
                                 "(no padding or blanks inside a field)")
        return self


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
#: the next move sets position mode up again).
ACUTROL3000 = TurntableProtocol(
    identify=Command(send="*IDN?", reply=r"(?P<identity>.+)", answer="{identity}"),
    move=Command(send=":demand:position {axis},{angle:.5f}"),
    multi_axis_move=True, move_separator=";",
    position=Command(send=":read:position? {axis}", reply=rf"(?P<angle>{_N})", answer="{angle:.5f}"),
    rate=Command(send=":read:rate? {axis}", reply=rf"(?P<rate>{_N})", answer="{rate:.5f}"),
    at_rest_deg_s=0.01, at_rest_polls=3,
    rotate=Command(send=":limit:rate R,{axis},{rate_limit:.5f};:limit:acceleration R,{axis},{acceleration:.5f};"
                   ":demand:rate {axis},{rate:.5f};:mode:rate {axis}"),
    hold=Command(send=":demand:rate {axis},0"),
    stop=Command(send=":demand:rate {axis},0;:mode:rate {axis};:demand:rate {axis},0"),
    home=Command(send=":demand:position {axis},0"),
    fault=Command(send=":interlock? {axis}", reply=r"(?P<fault>\w+)", answer="{fault}"),
    fault_values=["Fault", "Open"],  # tripped, or opened since the setup closed it
    setup=[Command(send=":interlock:close {axis}"), Command(send=":mode:position {axis}")],
    setup_pause_s=0.3,
)

PROTOCOLS: dict[str, TurntableProtocol] = {"accelcal-line": ACCELCAL_LINE, "acutrol3000": ACUTROL3000}


def turntable_protocol(name: str, overrides: dict[str, object] | None = None) -> TurntableProtocol:
    """A built-in profile with any fields the rig config overrides (validated)."""
    merged = {**PROTOCOLS[name].model_dump(), **(overrides or {})}
    return TurntableProtocol.model_validate(merged)
