"""How an ACUTROL3000 reads the ACL arguments that are not numbers (TM-8004-C), so that the simulator takes
exactly what a controller takes and refuses the rest.

- An enumerated argument is recognised "once a unique number of characters are entered", in any case
  (§2.7): `pos`, `rate`, `synt` are Position, Rate, Synthesis; `a` is no mode (Arate or Abort).
- A limit's mode may also be the Command Profiler's single letter (§4.6: A Abort, O Off, P Position, R Rate,
  S Synthesis, T Track), as the manual's own examples write it (`:LIM:ACC P,1,1500.0`).
- `ALL` may stand for the axis of a command, not of a query: the command then applies to every axis
  present (§2.4).
"""

from __future__ import annotations

#: The servo modes, as `:Mode <axis|ALL>,<mode>` (§4.7) and the Limit commands (§4.6) name them.
MODES = ("Position", "Rate", "Arate", "Synthesis", "Track", "Abort", "Off")
#: The Command Profiler's letter for each mode that has limits (§4.6); Arate has none there.
PROFILER_LETTERS = {"A": "Abort", "O": "Off", "P": "Position", "R": "Rate", "S": "Synthesis", "T": "Track"}
#: `:Utility:Lockout {ON | OFF}` (§4.14.2) and `:Utility:Format {BINary | FLOat}` (§4.14.1).
SWITCH = ("ON", "OFF")
FORMATS = ("BINary", "FLOat")
#: The axis argument meaning every axis present (§2.4).
ALL_AXES = "ALL"


def enumerated(text: str, values: tuple[str, ...]) -> str | None:
    """The value `text` names by a unique leading part, in any case (§2.7); None: no value or several."""
    wanted = text.casefold()
    if not wanted:
        return None
    exact = [value for value in values if value.casefold() == wanted]
    if exact:
        return exact[0]
    found = [value for value in values if value.casefold().startswith(wanted)]
    return found[0] if len(found) == 1 else None


def limit_mode(text: str) -> str | None:
    """A Limit command's mode: the profiler's letter (§4.6), else a mode named as §2.7 reads one; None: none
    that has limits."""
    letter = PROFILER_LETTERS.get(text.upper())
    if letter is not None:
        return letter
    mode = enumerated(text, MODES)
    return mode if mode in PROFILER_LETTERS.values() else None
