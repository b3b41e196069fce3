"""A request line as a simulated serial bridge reads it, by the reference firmware's rules (firmware/src/line.c;
docs/instruments.md, "The serial bridge protocol"): a CR is dropped wherever it is, a line of more than
MAX_LINE_BYTES bytes or with a byte outside printable ASCII is refused, words are split at spaces, and the start
of a line left a second without its LF is dropped. The pseudo-terminal hands the bridge each line as it came, one
character per byte (LINE_ENCODING, nothing stripped), so every byte is judged as the firmware judges it."""

from __future__ import annotations

from accelcal_rig.sim.bridge_refusals import LINE_TOO_LONG, NOT_PRINTABLE, Refusal

#: The longest request line, in bytes before its LF (CRs aside): the longest request is 8 ("R 7F 288").
MAX_LINE_BYTES = 64
#: A partial line this old is a previous client's, or noise: dropped.
STALE_LINE_S = 1.0
#: One character per byte, so a byte's value is the character's.
LINE_ENCODING = "latin-1"


def request_words(line: str) -> list[str]:
    """The words of a line as it came (without its LF): none for a line that is no request (empty, spaces).
    Refusal for a line too long or not printable ASCII, in that order."""
    kept = line.replace("\r", "")
    if len(kept) > MAX_LINE_BYTES:
        raise Refusal(LINE_TOO_LONG)
    if not all(" " <= character <= "~" for character in kept):
        raise Refusal(NOT_PRINTABLE)
    return [word for word in kept.split(" ") if word]


def overlong_line(head: str) -> str:
    """The answer to a line past the line reader's own bound (sim/line_answers.py), whatever it began with."""
    return "!" + LINE_TOO_LONG
