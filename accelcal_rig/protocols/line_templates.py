"""What line-protocol profiles share: request templates, reply patterns, and a request template read back
as a pattern (so that a simulator generated from a profile recognises the requests its driver sends)."""

from __future__ import annotations

import math
import re
import string
from collections.abc import Mapping
from typing import Any, ClassVar

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

#: A decimal number as controllers print them (sign, decimals, exponent optional).
NUMBER = r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"


def finite_number(text: str) -> float:
    """A request's number as a controller reads it: digits as NUMBER writes them (not Python's `nan`, `inf`,
    `1_0` or blanks, which float() would take) and finite (not `1e400`); ValueError otherwise, which a
    simulator answers with its profile's error."""
    if not re.fullmatch(NUMBER, text, re.ASCII):
        raise ValueError(f"not a number: {text!r}")
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"not a finite number: {text!r}")
    return value


def regular_expression(value: str) -> str:
    """A reply pattern must compile."""
    try:
        re.compile(value)
    except re.error as exc:
        raise ValueError(f"not a regular expression: {exc}") from None
    return value


def template(value: str, sample: Mapping[str, object]) -> str:
    """A template may name only the fields in `sample`, and must format with those values."""
    try:
        fields = [f for _, f, _, _ in string.Formatter().parse(value) if f is not None]
    except ValueError as exc:
        raise ValueError(f"not a template: {exc}") from None
    unknown = sorted(set(fields) - set(sample))
    if unknown:
        raise ValueError(f"template fields {', '.join(unknown)} unknown (known: {', '.join(sorted(sample))})")
    try:
        value.format(**sample)
    except (ValueError, TypeError, IndexError, KeyError) as exc:
        raise ValueError(f"template does not format: {exc}") from None
    return value


def fields_of(value: str) -> list[tuple[str, str]]:
    """(name, format spec) of each field a template names, in order."""
    return [(f, spec or "") for _, f, spec, _ in string.Formatter().parse(value) if f is not None]


def decimals_of(value: str, field: str) -> int | None:
    """The fixed decimals a template prints `field` with (`{value:.1f}` → 1); None if not fixed."""
    specs = [spec for name, spec in fields_of(value) if name == field]
    match = re.fullmatch(r"\.(\d+)f", specs[0]) if specs else None
    return int(match.group(1)) if match else None


def request_pattern(send: str) -> re.Pattern[str]:
    """The `send` template as a pattern: literal text as it is, each field a run of non-blank characters
    (a field named twice must read the same both times)."""
    pattern = ""
    seen: set[str] = set()
    for literal, field, _, _ in string.Formatter().parse(send):
        pattern += re.escape(literal)
        if field is not None:
            pattern += rf"(?P={field})" if field in seen else rf"(?P<{field}>\S+?)"
            seen.add(field)
    return re.compile(pattern)


class TemplateCommand(BaseModel):
    """One operation of a line protocol: what to send, the reply a good answer matches (none: the controller
    does not answer it), and what a controller answers, for the simulator made from the profile. A
    protocol family names the fields its requests and its answers may carry (class variables, with
    sample values that every template must format with)."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    send_fields: ClassVar[dict[str, Any]] = {}
    answer_fields: ClassVar[dict[str, Any]] = {}

    send: str = Field(min_length=1, max_length=256)
    reply: str | None = Field(None, min_length=1, max_length=256, description="regular expression a good reply "
                              "matches in full; none: the controller does not answer this command")
    answer: str | None = Field(None, min_length=1, max_length=256, description="what a controller answers "
                               "(template), for simulators")

    @field_validator("reply")
    @classmethod
    def _compiles(cls, value: str | None) -> str | None:
        return value if value is None else regular_expression(value)

    @field_validator("send")
    @classmethod
    def _fills(cls, value: str) -> str:
        return template(value, cls.send_fields)

    @field_validator("answer")
    @classmethod
    def _answers(cls, value: str | None) -> str | None:
        return value if value is None else template(value, {**cls.send_fields, **cls.answer_fields})

    @model_validator(mode="after")
    def _answered_if_replied(self) -> TemplateCommand:
        if (self.reply is None) != (self.answer is None):
            raise ValueError("a command has both a reply pattern and an answer, or neither")
        return self

    def request_pattern(self) -> re.Pattern[str]:
        """The `send` template as a pattern, for a simulator to recognise the request."""
        return request_pattern(self.send)
