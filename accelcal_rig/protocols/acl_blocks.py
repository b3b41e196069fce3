"""The ACUTROL3000's acknowledgement: on every interface but GPIB, each command gets a response, "an error code
and a message length ... prefixed to data that had been requested by a read or query command" (TM-8004-C §2).
Its layout is the ACL response block's (TM-9374A §3.4.2, the reflective-memory ACL channel): a 32-bit error
code (0: none), a 32-bit length in characters, then the response text; AcutronicRobotics' TCP client cuts
exactly eight bytes before the text and reads "OK" after a setting (acutrol.py send_command, ac117.json).

Not settled by any source we have: the byte order of the two words on TCP (written here little-endian, read
either way: a length is never above a few thousand), the error codes (TM-8004-C's Appendix C is not in the
public copy: the simulator answers 1 to a command it does not know), and whether a NUL follows the text (the
manual's block has one, the TCP client's "OK" comparison says not; a reader drops one if it comes)."""

from __future__ import annotations

import struct

PREFIX_BYTES = 8
#: The simulator's code for a command the controller does not know (see above: the manual's codes are unknown).
UNKNOWN_COMMAND = 1
#: A response longer than this is not a length: the bytes are not a prefix.
_MAX_LENGTH = 65536


def block(code: int, text: str) -> bytes:
    """A response block as the simulated controller sends it."""
    data = text.encode("ascii", errors="replace")
    return struct.pack("<iI", code, len(data)) + data


def prefix(data: bytes) -> tuple[int, int] | None:
    """(error code, length) from a block's first eight bytes in either byte order; None: they are not a
    prefix (text, or a length no response has)."""
    if len(data) < PREFIX_BYTES:
        return None
    for order in ("<", ">"):
        code, length = struct.unpack(f"{order}iI", data[:PREFIX_BYTES])
        if length <= _MAX_LENGTH and abs(code) <= _MAX_LENGTH:
            return code, length
    return None


def looks_like_prefix(data: bytes) -> bool:
    """Whether a reply line starts with a block's prefix rather than text (its first bytes unprintable)."""
    head = data[:PREFIX_BYTES]
    return len(head) == PREFIX_BYTES and any(byte < 0x20 and byte not in (0x0A, 0x0D, 0x09) for byte in head)


def is_block(data: bytes) -> bool:
    """Whether `data` is exactly one response block (a NUL after its text allowed): what a controller that
    acknowledges every command sent, read by a reader that expected a line."""
    found = prefix(data)
    return found is not None and looks_like_prefix(data) and len(data.rstrip(b"\0")) == PREFIX_BYTES + found[1]
