"""What a simulated serial bridge answers a request it refuses: `!` and one of these texts, worded once here exactly
as the reference firmware words them (firmware/src/commands.c, bridge.c), so a driver meets the same refusals
from either; docs/instruments.md ("The serial bridge protocol") lists them. ASCII, short, and never a message of
the language the simulator is written in."""

from __future__ import annotations


class Refusal(Exception):
    """A request the bridge refuses: its reply is `!` and this exception's text."""


LINE_TOO_LONG = "line too long"
NOT_PRINTABLE = "not printable ASCII"
UNKNOWN_REQUEST = "unknown request (? R W C G)"
BAD_ADDRESS = "bad address (hex 00..7F)"
BAD_VALUE = "bad value (hex 00..FF)"
FIFO_CAPTURED = "FIFO_DATA is being captured (fetch with G)"
NO_CAPTURE = "no capture (start one with C)"
NEEDS_MEASURING = "capture needs the part measuring"


def usage(verb: str, arguments: str) -> str:
    return f"usage: {verb}{' ' + arguments if arguments else ''}"


def bad_count(most: int) -> str:
    return f"bad count (decimal 1..{most})"


def bad_first(most: int) -> str:
    return f"bad first (decimal 0..{most})"


def no_register(address: int) -> str:
    return f"no register 0x{address:02X}"


def read_only(address: int) -> str:
    return f"read-only register 0x{address:02X}"


def standby_only(address: int) -> str:
    return f"register 0x{address:02X} changes only in standby"


def capture_stopped(register: int, have: int, wanted: int) -> str:
    return f"capture stopped: register 0x{register:02X} written after {have} of {wanted} samples"


def fifo_not_in_packets(fifo_config: int, fifo_config1: int) -> str:
    """An ICM-42688-P's FIFO off, or not in packets of both sensors (FIFO_CONFIG, FIFO_CONFIG1 as read)."""
    return f"capture needs the FIFO on with both sensors (FIFO_CONFIG {fifo_config:02X}, FIFO_CONFIG1 {fifo_config1:02X})"


def capture_not_supported(part: str) -> str:
    return f"capture: not supported for {part}"
