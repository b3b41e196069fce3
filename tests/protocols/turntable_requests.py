"""Conformance from the makers' side, for the `acutrol3000` profile, as data: the exact requests the public
ACL clients send and the manual's own examples (each cited: repository, path and function or line; the
manual's section), in the order a session sends them, and what must come of each on the simulated
ACUTROL3000: understood as profile operations (the reply, one value per query joined by `;`, read by the
driver's own parser), answered as the manual documents, refused (the profile's error reply), or unanswered
(a setting).

tests/protocols/test_turntable_requests.py replays them on a pty. Requests are written without their line
terminator. What the clients send that the simulator does not model is in NOT_SIMULATED, with the reason,
and is answered as an unknown request. Facts: docs/instruments.md, "`acutrol3000`".
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Row:
    request: str
    where: str
    operations: tuple[str, ...] = ()  # each query's reply (joined by `;`) read by this operation's pattern
    reply: str | None = None  # a regular expression the whole reply must match
    refused: bool = False  # answered with the profile's error reply; nothing moves
    silent: bool = False  # a setting: no reply
    axis1_deg: float | None = None  # afterwards (and time to get there) axis 1 reads this angle


@dataclass(frozen=True)
class Conversation:
    client: str  # owner/repository, or the manual
    licence: str
    rows: tuple[Row, ...]


_IEAV = "python/acutrol3000.py"
_ACR = "acutrol.py"
_N = r"-?\d+\.\d+"

CONVERSATIONS: tuple[Conversation, ...] = (
    Conversation("IEAv-EFO/acutrol3000", "none stated", (
        Row("*idn?", f"{_IEAV} __init__ (line 6)", ("identify",)),
        Row(":mode:off 1", f"{_IEAV} initialise (lines 52-58)", silent=True),
        Row(":int:close 1", f"{_IEAV} initialise (lines 52-58)", silent=True),
        Row(":interlock? 1", f"{_IEAV} interlock check (line 41)", ("fault",)),
        Row("*stb?", f"{_IEAV} status byte (line 44; 65 is its interlock error)", reply="0"),
        Row(":mode? 1", f"{_IEAV} read_mode (lines 121, 148, 164; it compares Rate/Position, the manual "
            "shows P/R)", reply="O"),
        Row(":read:pos? 1", f"{_IEAV} read_position (lines 24-34)", ("position",)),
        Row(":read:rate? 1", f"{_IEAV} read_rate (lines 24-34)", ("rate",)),
        Row(":dem:rate 1,0", f"{_IEAV} stop (lines 72-78, 185-190)", silent=True),
    )),
    Conversation("AcutronicRobotics/acutrol", "MIT", (
        Row(":interlock:close 1", f"{_ACR} ac117.json startup list, send_command_list (it expects OK: not "
            "settled)", silent=True),
        Row(":mode:position 1", f"{_ACR} command_position", silent=True),
        Row(":demand:position 1, 045.000", f"{_ACR} command_position ('%06.3f', a blank after the comma)",
            silent=True, axis1_deg=45.0),
        Row(":read:position 1", f"{_ACR} status (no '?')", ("position",)),
        Row(":read:rate 1", f"{_ACR} status (no '?')", ("rate",)),
        Row(":mode:off 1", f"{_ACR} ac117.json shutdown list", silent=True),
        Row(":demand:position 1, 010.000", f"{_ACR} command_position, without position mode: the axis stays",
            silent=True, axis1_deg=45.0),
    )),
    Conversation("Acutronic TM-8004-C (ACL Programming Manual), examples", "manual", (
        Row(":I:C 1;C 2;C 3", "§4.5.1 (:I:C 1;C 2)", silent=True),
        Row(":M:P 1;P 2;P 3", "§4.7.4 (:M:P 1;P 2)", silent=True),
        Row(":M? 1;:M? 2;:M? 3", "§4.7 (→ P;R;P)", reply="P;P;P"),
        Row(":Dem:Pos 1,10.5;Pos 2,0.01;Pos 3,0", "§2.3 (:Demand:Pos 2,0.01;Rate 3,100)", silent=True,
            axis1_deg=10.5),
        Row(":R:P? 1;P? 2;P? 3", "§4.10.4 (→ 10.0001;44.1250;0.0001)", ("position",) * 3,
            reply=rf"{_N};{_N};{_N}"),
        Row(":READ:RATE? 1", "§4.10.5", ("rate",)),
        Row(":read:pos? 1;rate? 1", "§4.10.5 (:R:R? 2;:R:P? 1 → rate;position), chained as IEAv does",
            ("position", "rate")),
        Row(":D:P 3,10.5", "§2.1", silent=True),
        Row(":DEM:POS 1,135.223", "§4.3.5", silent=True, axis1_deg=135.223),
        Row(":MODE? 2", "§4.7 (→ P)", reply="P"),
        Row("*STB?", "§3.10", reply="0"),
        Row(":Demand:Posn 3,10.5", "§2.1: an error (spelling)", refused=True, axis1_deg=135.223),
        Row(":Dem;Pos 3,10.50000", "§2.1: an error (misuse of semicolon)", refused=True),
        Row(":D:P,3,10.5", "§2.1: an error (a comma between command and arguments)", refused=True),
        Row(":Mode? ALL", "§2.4: ALL is an error for a query", refused=True),
        Row(":D:P 1,0;:D:Q 2,0", "a bad command in a line: the whole line is refused, nothing moves",
            refused=True, axis1_deg=135.223),
        Row(":MODE:OFF 1", "§4.7.3", silent=True),
        Row(":MODE? 1", "§4.7", reply="O"),
    )),
)

#: (request, client, where, why the simulator does not serve it): sent by a public client, understood by a
#: real controller, answered by the simulated one as an unknown request (`ERR unknown command …`).
NOT_SIMULATED: tuple[tuple[str, str, str, str], ...] = (
    (":read:pos? 1;rate? 1;acc? 1", "IEAv-EFO/acutrol3000", f"{_IEAV} line 14",
     "no acceleration read-back (Read:Acceleration): the whole chained line is refused"),
    (":read:acc? 1", "IEAv-EFO/acutrol3000", f"{_IEAV} lines 24-34", "no acceleration read-back"),
    (":Interlock:Reset", "IEAv-EFO/acutrol3000", f"{_IEAV} initialise", "no frozen interlock status to reset"),
    (":interlock:reset 1", "AcutronicRobotics/acutrol", f"{_ACR} ac117.json", "no frozen interlock status"),
    (":int:open 1", "IEAv-EFO/acutrol3000", f"{_IEAV} terminate (line 67)", "the interlock is not modelled "
     "beyond the profile's close"),
    (":interlock:open 1", "AcutronicRobotics/acutrol", f"{_ACR} ac117.json", "as above"),
    (":utility:lockout on", "AcutronicRobotics/acutrol", f"{_ACR} ac117.json", "no local panel to lock out"),
    (":mode:synt 1", "IEAv-EFO/acutrol3000", f"{_IEAV} stop (lines 72-78)", "no synthesis (sine) mode"),
    (":dem:osc 1,0,0,0", "IEAv-EFO/acutrol3000", f"{_IEAV} stop", "no oscillator demand"),
    (":mode:rate 1", "IEAv-EFO/acutrol3000", f"{_IEAV} stop; also {_ACR} command_rate", "rate mode is "
     "carried out as the profile's rotate and stop sequences, not as a mode change alone"),
    (":demand:rate 1, 010.000", "AcutronicRobotics/acutrol", f"{_ACR} command_rate", "a rate demand other "
     "than the profile's hold (zero) is carried out only within its rotate sequence"),
    (":mode 1,rate", "IEAv-EFO/acutrol3000", f"{_IEAV} send_rate (lines 113-171)", "the one-command mode "
     "form (:Mode <axis>,<mode>) is not modelled"),
    (":mode 1,pos", "IEAv-EFO/acutrol3000", f"{_IEAV} send_position", "as above"),
    (":dem:delta 1,5.0", "IEAv-EFO/acutrol3000", f"{_IEAV} relative move", "no relative position demand"),
    (":limit:absolute? 1", "IEAv-EFO/acutrol3000", f"{_IEAV} line 87", "no factory limits table"),
    (":limit:acc? pos,1", "IEAv-EFO/acutrol3000", f"{_IEAV} lines 90-95", "limits are set only within the "
     "profile's rotate sequence, not read back"),
    (":lim:acc pos,1,100.0", "IEAv-EFO/acutrol3000", f"{_IEAV} set_limits (lines 104-109)", "as above"),
    (":m:p ALL", "IEAv-EFO/acutrol3000", "examples/routine_example.cfg (a macro file)", "ALL as the axis of a "
     "command is not modelled"),
)
