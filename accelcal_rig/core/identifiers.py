"""A DUT's serial is an identifier, wherever one enters (a rig config, a calibration file, a recording's name or
`--serial`, a campaign read back): it names files (certificates, exports), registry rows and dashboard
addresses, so it holds no path separator, no control character and no leading dot or dash (`..` is no serial)."""

from __future__ import annotations

import re

from accelcal_rig.errors import ConfigError

#: 1–64 characters: letters, digits, `_`, `.`, `-`, beginning with a letter or a digit.
SERIAL_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"
_SERIAL = re.compile(SERIAL_PATTERN)


def is_serial(text: str) -> bool:
    return bool(_SERIAL.fullmatch(text))


def checked_serial(text: str, where: str) -> str:
    """`text` if it is a serial; else one line naming `where` it came from."""
    if not is_serial(text):
        shown = "".join(c if c.isprintable() else "?" for c in text[:80])
        raise ConfigError(f"{where}: serial {shown!r} is not an identifier: 1–64 letters, digits, _ . -, beginning "
                          "with a letter or a digit")
    return text
