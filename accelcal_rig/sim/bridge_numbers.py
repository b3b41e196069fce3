"""The serial bridge's two kinds of number, read as strictly as the reference firmware reads them
(firmware/src/parse.c): a byte is one or two hex digits in either case; a count is decimal digits only (no sign,
leading zeros allowed, any length). Anything else is no number: None, never a guess."""

from __future__ import annotations

import re

_HEX_BYTE = re.compile(r"[0-9A-Fa-f]{1,2}")
_DECIMAL = re.compile(r"[0-9]+")


def hex_byte(text: str) -> int | None:
    return int(text, 16) if _HEX_BYTE.fullmatch(text) else None


def decimal(text: str, most: int) -> int | None:
    """The number, or None if `text` is none or it is above `most`."""
    if not _DECIMAL.fullmatch(text):
        return None
    value = int(text)
    return value if value <= most else None
