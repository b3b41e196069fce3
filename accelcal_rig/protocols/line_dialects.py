"""How a controller family reads a request, beyond the literal text of a profile's template: the spelling
the driver sends (the makers' own libraries'), every spelling the controller takes (what its simulator
must understand), and what a template must be to be sent at all.

- `plain`: the text as written (Thermotron).
- `espec`: a blank after a comma is optional (ESPEC's library sends `MODE,CONSTANT` and `TEMP, S25.0`;
  other clients `MODE, CONSTANT` and `TEMP,S25.0`).
- `simserv`: numbered commands; a template must be a known command number with a field count it takes.
- `scpi`: SCPI program headers (scpi_headers.py): templates in the manuals' notation, sent as upper-case
  long forms, read in any documented spelling.
- `acl` (turntables): Acutronic's ACL (acl_messages.py): the same notation, sent as lower-case long forms,
  each mnemonic read cut anywhere from its short form on; a request pattern is of the message's commands
  from the root, joined by `;` (acl_messages.commands).
"""

from __future__ import annotations

import re
import string
from collections.abc import Callable
from typing import Literal

from accelcal_rig.protocols import acl_messages, scpi_headers, simserv_commands

#: A chamber profile's dialects.
Dialect = Literal["plain", "espec", "simserv", "scpi"]
#: Every dialect (a turntable profile's are `plain` and `acl`).
LineDialect = Literal["plain", "espec", "simserv", "scpi", "acl"]


def spelled(send: str, dialect: LineDialect) -> str:
    """The template as the driver sends it (SCPI: the header's upper-case long form; ACL: lower-case)."""
    if dialect == "acl":
        return acl_messages.spelled(send)
    if dialect != "scpi":
        return send
    header, parameters = scpi_headers.split_request(send)
    long_form = scpi_headers.read_notation(header).long_form()
    return f"{long_form} {parameters}" if parameters else long_form


def check(send: str, dialect: LineDialect) -> None:
    """ValueError where a template cannot be sent as the family's controllers read requests."""
    if dialect == "acl":
        acl_messages.check(send)
    elif dialect == "simserv":
        simserv_commands.check_request(send)
    elif dialect == "scpi":
        scpi_headers.read_notation(scpi_headers.split_request(send)[0])


def request_pattern(send: str, dialect: LineDialect) -> re.Pattern[str]:
    """Every request the controller reads as this template's: literal text as the dialect reads it, each
    field a run of non-blank characters (a field named twice must read the same both times)."""
    if dialect == "acl":
        return re.compile(acl_messages.request_pattern(send))
    if dialect == "scpi":
        header, parameters = scpi_headers.split_request(send)
        head = scpi_headers.read_notation(header).pattern()
        return re.compile(head + (r"\s+" + _fields_pattern(parameters, _scpi_literal) if parameters else ""))
    return re.compile(_fields_pattern(send, _espec_literal if dialect == "espec" else re.escape))


def _fields_pattern(send: str, literal: Callable[[str], str]) -> str:
    pattern = ""
    seen: set[str] = set()
    for text, field, _, _ in string.Formatter().parse(send):
        pattern += literal(text)
        if field is not None:
            pattern += rf"(?P={field})" if field in seen else rf"(?P<{field}>\S+?)"
            seen.add(field)
    return pattern


def _espec_literal(text: str) -> str:
    """A comma with or without one blank after it."""
    return "".join(", ?" if piece in (",", ", ") else re.escape(piece) for piece in re.split(r"(, ?)", text))


def _scpi_literal(text: str) -> str:
    """Character data in any case; blanks as one or more."""
    return "".join(r"\s+" if piece.isspace() else f"(?i:{re.escape(piece)})" if piece else ""
                   for piece in re.split(r"(\s+)", text))
