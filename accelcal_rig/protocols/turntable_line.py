"""Turntable controller line protocols as data: command templates, reply patterns, terminators.

A profile says, for each operation, what to send (a template with `{axis}`, 1-based, and `{angle}`),
the pattern a good reply must match (named groups carry values), and — so that a simulator can speak
the same profile — the answer template a controller gives. Any reply matching `error_pattern` is a
controller error.
"""

from __future__ import annotations

import re

from pydantic import BaseModel, ConfigDict, Field, field_validator

from accelcal_rig.protocols.line_templates import regular_expression, request_pattern, template

#: What a template may name, with sample values: the request's axis (1-based) and angle, and the values
#: replies carry.
_TEMPLATE_SAMPLE: dict[str, object] = {"axis": 1, "angle": 0.0, "identity": "x", "busy": 0, "fault": 0}


class Command(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    send: str = Field(min_length=1, max_length=256)
    reply: str = Field(min_length=1, max_length=256, description="regular expression a good reply matches in full")
    answer: str = Field(min_length=1, max_length=256, description="what a controller answers (template), for "
                        "simulators")

    _compiles = field_validator("reply")(classmethod(lambda cls, value: regular_expression(value)))
    #: `{axis}` and `{angle:.5f}` style fields, nothing a request cannot fill.
    _templates = field_validator("send", "answer")(classmethod(lambda cls, value: template(value, _TEMPLATE_SAMPLE)))

    def request_pattern(self) -> re.Pattern[str]:
        """The `send` template as a pattern, for a simulator to recognise the request."""
        return request_pattern(self.send)


class TurntableProtocol(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    write_terminator: str = Field("\n", min_length=1, max_length=4)
    read_terminator: str = Field("\n", min_length=1, max_length=4)
    error_pattern: str = Field("^ERR", max_length=256)
    identify: Command
    move: Command
    position: Command
    busy: Command
    stop: Command
    home: Command
    fault: Command
    busy_values: list[str] = Field(["1"], max_length=16)
    fault_ok: list[str] = Field(["0"], max_length=16)

    _compiles = field_validator("error_pattern")(classmethod(lambda cls, value: regular_expression(value)))


#: The built-in profile: a plain SCPI-like line protocol, one command per line, one reply per command.
ACCELCAL_LINE = TurntableProtocol(
    identify=Command(send="*IDN?", reply=r"(?P<identity>.+)", answer="{identity}"),
    move=Command(send="MOV {axis} {angle:.5f}", reply="OK", answer="OK"),
    position=Command(send="POS? {axis}", reply=r"(?P<angle>[-+]?\d+(\.\d*)?([eE][-+]?\d+)?)", answer="{angle:.6f}"),
    busy=Command(send="BUSY?", reply=r"(?P<busy>[01])", answer="{busy}"),
    stop=Command(send="STOP", reply="OK", answer="OK"),
    home=Command(send="HOME", reply="OK", answer="OK"),
    fault=Command(send="FAULT?", reply=r"(?P<fault>\d+)", answer="{fault}"),
)

PROTOCOLS: dict[str, TurntableProtocol] = {"accelcal-line": ACCELCAL_LINE}


def turntable_protocol(name: str, overrides: dict[str, object] | None = None) -> TurntableProtocol:
    """A built-in profile with any fields the rig config overrides (validated)."""
    merged = {**PROTOCOLS[name].model_dump(), **(overrides or {})}
    return TurntableProtocol.model_validate(merged)
