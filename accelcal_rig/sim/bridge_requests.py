"""A simulated serial bridge's answer to each line (docs/instruments.md, "The serial bridge protocol"), checked in
the reference firmware's order (firmware/src/commands.c): the line (sim/bridge_lines.py), the verb and its number
of words, whether the part has the request, then the request's own checks (R and W: sim/bridge_registers.py; C
and G: sim/bridge_capture.py). A refusal is `!` and its text (sim/bridge_refusals.py); a line with no words gets
no reply."""

from __future__ import annotations

from collections.abc import Callable

from accelcal_rig.sim.bridge_capture import CaptureRequests
from accelcal_rig.sim.bridge_lines import request_words
from accelcal_rig.sim.bridge_refusals import UNKNOWN_REQUEST, Refusal, capture_not_supported, usage
from accelcal_rig.sim.bridge_registers import RegisterRequests

#: Each request's arguments, as its refusal for a wrong number of words names them.
_ARGUMENTS = {"?": "", "R": "<addr> <count>", "W": "<addr> <value>", "C": "<count>", "G": "<first>"}


class BridgeRequests:
    """The requests of one bridge in front of its part named `part`: the greeting, R and W, and C and G where the
    bridge captures (`capture`; None: refused, naming the part). `verbs` are the requests its protocol version
    knows (version 1 has no C and G)."""

    def __init__(self, greeting: Callable[[], str], registers: RegisterRequests, part: str,
                 capture: CaptureRequests | None = None, verbs: str = "?RWCG") -> None:
        self._greeting = greeting
        self._registers = registers
        self._part = part
        self._capture = capture
        self._verbs = frozenset(verbs)

    def answer(self, line: str) -> str | None:
        """The reply to a line as it came (one character per byte, without its LF); None: no reply."""
        try:
            words = request_words(line)
            return self._answer(words[0], words[1:]) if words else None
        except Refusal as refusal:
            return f"!{refusal}"

    def _answer(self, verb: str, arguments: list[str]) -> str:
        if verb not in _ARGUMENTS or verb not in self._verbs:
            raise Refusal(UNKNOWN_REQUEST)
        if len(arguments) != len(_ARGUMENTS[verb].split()):
            raise Refusal(usage(verb, _ARGUMENTS[verb]))
        if verb == "?":
            self._registers.select_bank_0()
            return self._greeting()
        if verb == "R":
            return self._registers.read(*arguments)
        if verb == "W":
            return self._registers.write(*arguments)
        if self._capture is None:
            raise Refusal(capture_not_supported(self._part))
        return self._capture.start(arguments[0]) if verb == "C" else self._capture.fetch(arguments[0])
