"""SCPI program headers as the manuals write them and as instruments read them (SCPI-99 vol. 1, §6–7).

A manual writes each mnemonic with its short form in upper case and the rest of its long form in lower
case (`:SOURce:CLOop1:SPOint`): an instrument takes either form, in any case, with or without the leading
colon, and a numeric suffix of 1 may be left out (`CLOop` is `CLOop1`). A mnemonic written all in upper
case (`UNIT`) has one form. A profile's SCPI templates are written in that notation; the driver sends the
long form in upper case (the makers' libraries' spelling), and the simulator reads any spelling the
notation allows. Acutronic's ACL (acl_messages.py) reads the same notation more loosely: a mnemonic may be
cut anywhere from its short form to its long form.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: One mnemonic in the manuals' notation: short form (capitals), rest of the long form (lower case), suffix.
_NOTATION = re.compile(r"(?P<short>[A-Z]+)(?P<rest>[a-z]*)(?P<suffix>\d*)")
#: A common command (IEEE 488.2): `*IDN?`, `*RST`.
_COMMON = re.compile(r"\*[A-Za-z]{3}\??")


@dataclass(frozen=True)
class Mnemonic:
    short: str
    long: str
    suffix: str

    def pattern(self) -> str:
        """Either form, in any case; a suffix of 1 may be left out, any other must be given."""
        forms = "|".join(re.escape(form) for form in dict.fromkeys((self.long, self.short)))
        suffix = "1?" if self.suffix in ("", "1") else re.escape(self.suffix)
        return f"(?i:{forms}){suffix}"

    def abbreviation_pattern(self) -> str:
        """Any leading part of the long form from the short form on, in any case (ACL: `:D:P`, `:Dem:Pos`,
        `:Demand:Position` are one command, `:Demand:Posn` is an error); a suffix only as written."""
        tail = ""
        for character in reversed(self.long[len(self.short):]):
            tail = f"(?:{re.escape(character)}{tail})?"
        return f"(?i:{re.escape(self.short)}{tail}){re.escape(self.suffix)}"


@dataclass(frozen=True)
class Header:
    colon: bool
    mnemonics: tuple[Mnemonic, ...]
    query: bool
    common: str | None = None

    def long_form(self, lower: bool = False) -> str:
        """The header as the makers' libraries send it: long forms, upper case (`lower`: lower case, as
        Acutronic's clients write ACL; a common command then as written), suffixes written."""
        if self.common is not None:
            return self.common if lower else self.common.upper()
        text = ":".join((m.long.lower() if lower else m.long) + m.suffix for m in self.mnemonics)
        return (":" if self.colon else "") + text + ("?" if self.query else "")

    def pattern(self) -> str:
        """Every spelling of the header an instrument takes, as a regular expression."""
        if self.common is not None:
            return f"(?i:{re.escape(self.common)})"
        return ":?" + ":".join(m.pattern() for m in self.mnemonics) + (r"\?" if self.query else "")


def split_request(text: str) -> tuple[str, str]:
    """(header, parameters): a program header ends at the first blank."""
    header, _, parameters = text.partition(" ")
    return header, parameters.lstrip(" ")


def read_notation(header: str) -> Header:
    """A header in the manuals' notation; ValueError saying how to write it otherwise."""
    if _COMMON.fullmatch(header):
        return Header(False, (), header.endswith("?"), common=header)
    colon, body = header.startswith(":"), header.removeprefix(":")
    query, body = body.endswith("?"), body.removesuffix("?")
    mnemonics = []
    for part in body.split(":"):
        match = _NOTATION.fullmatch(part)
        if match is None:
            raise ValueError(f"{header!r} is not a SCPI header in the manuals' notation (each mnemonic's short "
                             "form in upper case, the rest of its long form in lower case, then any suffix: "
                             "':SOURce:CLOop1:SPOint')")
        short, rest, suffix = match.group("short", "rest", "suffix")
        mnemonics.append(Mnemonic(short, (short + rest).upper(), suffix))
    return Header(colon, tuple(mnemonics), query)
