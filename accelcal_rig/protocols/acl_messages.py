"""Acutronic's ACL as an ACUTROL3000 reads a message (TM-8004-C §2.1–2.4, 4.10), so that a profile's
templates are checked, spelled and recognised as the controller does.

- Headers are written in the manual's notation (scpi_headers.py) with the short form the shortest spelling
  the manual shows (`:Demand:Position`, since `:D:P 3,10.5` is one of its examples); a controller reads any
  leading part of each long form from there on, in any case (`:DEM:POS`, `:dem:pos`, `:Demand:Pos`), and
  a misspelling (`:Demand:Posn`) is an error. The driver sends lower-case long forms, as both public
  clients do.
- The header ends at a blank: `:D:P,3,10.5` is an error; a blank may follow each comma between arguments.
- The Read queries (§4.10.1, 4.10.4, 4.10.5) may leave out their `?` "for ACT2000 compatibility".
- One line may carry several commands joined by `;`: one starting with `:` starts at the root, one
  without continues at the level of the command before it (`:R:P? 1;P? 2` is `:R:P? 1;:R:P? 2`); the
  first may leave out its colon. Each of a profile's commands starts at the root, so that it reads the
  same whatever line it is joined into.
- Blanks around a `;` are not part of either command (`:u:f f ; :R:P 1`, as the williamsea client sends)
  [inferred: the manual's syntax (§2) shows none; IEEE-488.2, which §2.1 follows, lets white space precede
  a message unit]. Inside a header a blank still ends it (§2.3: a compound header contains no white space).
"""

from __future__ import annotations

import re
import string

from accelcal_rig.protocols import scpi_headers

SEPARATOR = ";"
#: Queries whose `?` may be left out (TM-8004-C §4.10: "For ACT2000 compatibility, the ? is not required").
_QUESTION_OPTIONAL = "READ"


def commands(message: str) -> list[str]:
    """The message's commands, each from the root (`:` and its whole header), its arguments as sent; a
    trailing `;` ends nothing more (`:A:C? 7;` is one of the manual's examples)."""
    parts = [part.strip(" \t") for part in message.split(SEPARATOR)]
    if len(parts) > 1 and parts[-1] == "":
        parts.pop()
    rooted: list[str] = []
    level: list[str] = []
    for index, part in enumerate(parts):
        header, blank, arguments = part.partition(" ")
        if header.startswith("*"):  # a common command: the level stays
            rooted.append(part)
            continue
        query, body = header.endswith("?"), header.removesuffix("?")
        if body.startswith(":"):
            path = body[1:].split(":")
        else:  # the first command starts at the root anyway; a later one continues at the level before it
            path = body.split(":") if index == 0 else [*level, *body.split(":")]
        level = path[:-1]
        rooted.append(":" + ":".join(path) + ("?" if query else "") + blank + arguments)
    return rooted


def spelled(send: str) -> str:
    """The template as the driver sends it: each header's long form in lower case, arguments as written."""
    pieces = []
    for part in send.split(SEPARATOR):
        header, arguments = scpi_headers.split_request(part)
        long_form = scpi_headers.read_notation(header).long_form(lower=True)
        pieces.append(f"{long_form} {arguments}" if arguments else long_form)
    return SEPARATOR.join(pieces)


def check(send: str) -> None:
    """ValueError where a template is not ACL a controller reads as the template's own commands."""
    for part in send.split(SEPARATOR):
        header = part.partition(" ")[0]
        if not header.startswith((":", "*")):
            raise ValueError(f"{part!r} does not start at the root (':'): joined after another command it "
                             "would be read at that command's level")
        if "," in header:
            raise ValueError(f"{part!r}: a blank, not a comma, ends the header (TM-8004-C §2.1: ':D:P,3,10.5' "
                             "is an error)")
        scpi_headers.read_notation(header)


def request_pattern(send: str) -> str:
    """Every spelling of the template's commands, from the root (commands()), joined by `;`; each field
    a run of non-blank characters (a field named twice must read the same both times)."""
    pieces = []
    seen: set[str] = set()
    for part in send.split(SEPARATOR):
        header_text, arguments = scpi_headers.split_request(part)
        header = scpi_headers.read_notation(header_text)
        if header.common is not None:
            head = header.pattern()
        else:
            question = ""
            if header.query:
                optional = header.mnemonics[0].long == _QUESTION_OPTIONAL
                question = r"\??" if optional else r"\?"
            head = ":" + ":".join(m.abbreviation_pattern() for m in header.mnemonics) + question
        pieces.append(head + (" +" + _arguments(arguments, seen) if arguments else ""))
    return re.escape(SEPARATOR).join(pieces)


def _arguments(template: str, seen: set[str]) -> str:
    pattern = ""
    for text, field, _, _ in string.Formatter().parse(template):
        pattern += "".join(",[ \t]*" if piece == "," else f"(?i:{re.escape(piece)})" if piece else ""
                           for piece in re.split(r"(,)", text))
        if field is not None:
            pattern += rf"(?P={field})" if field in seen else rf"(?P<{field}>[^\s,;]+)"
            seen.add(field)
    return pattern
