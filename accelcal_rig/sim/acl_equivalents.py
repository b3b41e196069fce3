"""Commands an ACUTROL3000 reads as others (TM-8004-C), rewritten to those, so that a simulated controller
carries out one command however the manual lets it be written:

- `ALL` as the axis of a command (not a query) applies it "to all axes that are present" (§2.4):
  `:M:P ALL` is `:M:P 1;:M:P 2;:M:P 3` on a three-axis table. A query naming `ALL` is left as it is, for
  the reader to refuse ("an error will result ... if ALL is used for a query").
- The one-command mode form `:Mode <axis>,<mode>` (§4.7) is the mode's own command, `:Mode:<mode> <axis>`
  (§4.7.1–4.7.7: "the sub-sections define Acutrol Act 2000 compliant commands that function as well"),
  the mode read as §2.7 reads an enumerated argument (`pos`, `rate`).
"""

from __future__ import annotations

import re

from accelcal_rig.protocols.acl_arguments import ALL_AXES, MODES, enumerated
from accelcal_rig.protocols.acl_messages import request_pattern

_MODE_FORM = re.compile(request_pattern(":Mode {axis},{mode}"))


def rewritten(commands: list[str], n_axes: int) -> list[str]:
    """Each command from the root (acl_messages.commands) as the command(s) the controller carries out."""
    out: list[str] = []
    for command in commands:
        for each in _every_axis(command, n_axes):
            out.append(_mode_command(each))
    return out


def _every_axis(command: str, n_axes: int) -> list[str]:
    header, blank, arguments = command.partition(" ")
    values = [value.strip() for value in arguments.split(",")] if blank else []
    if header.endswith("?") or not any(value.upper() == ALL_AXES for value in values):
        return [command]
    return [f"{header} " + ",".join(str(axis) if value.upper() == ALL_AXES else value for value in values)
            for axis in range(1, n_axes + 1)]


def _mode_command(command: str) -> str:
    match = _MODE_FORM.fullmatch(command)
    if match is None:
        return command
    mode = enumerated(match["mode"], MODES)
    return command if mode is None else f":Mode:{mode} {match['axis']}"
