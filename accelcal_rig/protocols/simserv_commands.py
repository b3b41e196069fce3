"""Vötsch/Weiss SIMSERV command numbers and how many ¶-separated fields follow each (the chamber index
first), as the public clients send them (sources: docs/instruments.md). A controller answers `-5` to a number
it does not know and `-6` to a known one with too few or wrong parameters; a profile's request must be one
of these with a count it takes."""

from __future__ import annotations

#: The field separator (byte 0xB6 in latin-1).
SEPARATOR = "\u00b6"

#: Command number → the field counts it takes after the number (the chamber index is the first field).
FIELDS: dict[str, frozenset[int]] = {
    "99997": frozenset({2}),          # chamber info: index, selector (1 type, 2 year, 3 serial number)
    "10012": frozenset({1, 2}),       # chamber status: IzaakWN sends the index alone, basil one more field
    "11001": frozenset({3}),          # set point of control variable n: index, n, value
    "11002": frozenset({2}),          # set point of control variable n
    "11004": frozenset({2}),          # actual value of control variable n (1 temperature, 2 humidity)
    "11007": frozenset({2}),          # input limit min
    "11009": frozenset({2}),          # input limit max
    "11014": frozenset({2}), "11015": frozenset({2}),  # alarm limits min / max
    "11016": frozenset({2}), "11017": frozenset({2}),  # warning limits min / max
    "11018": frozenset({1}),          # number of control variables
    "11023": frozenset({2}),          # unit of control variable n
    "11026": frozenset({2}),          # name of control variable n
    "11066": frozenset({2}), "11070": frozenset({2}),  # gradient up / down of control variable n
    "11068": frozenset({3}), "11072": frozenset({3}),  # set gradient up / down: index, n, value
    "14001": frozenset({3}),          # set digital output n: index, n, 0|1 (output 1 is the manual run)
    "14003": frozenset({2}),          # read digital output n
    "14007": frozenset({1}),          # number of digital outputs
    "14010": frozenset({2}),          # name of digital output n
    "17002": frozenset({1}),          # number of messages (IzaakWN checkActiveWarnings: the index alone)
    "19204": frozenset({1}),          # number of the program running (IzaakWN getRunStatus)
    "19210": frozenset({1}),          # program status: 0 not running, 1 running, +2 paused (IzaakWN forceWarmUp)
}


def command_fields(request: str) -> tuple[str, list[str]]:
    """(command number, the fields after it) of a request."""
    number, *fields = request.split(SEPARATOR)
    return number, fields


def check_request(send: str) -> None:
    """A profile's request must be a known command number with a field count it takes (ValueError)."""
    number, fields = command_fields(send)
    if number not in FIELDS:
        raise ValueError(f"{send!r}: SIMSERV has no command {number!r} (known: {', '.join(sorted(FIELDS))})")
    if len(fields) not in FIELDS[number]:
        counts = " or ".join(str(n) for n in sorted(FIELDS[number]))
        raise ValueError(f"{send!r}: SIMSERV command {number} takes {counts} fields after its number (chamber index "
                         f"first), not {len(fields)} (the controller answers -6)")
