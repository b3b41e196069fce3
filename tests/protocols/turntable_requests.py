"""Conformance from the makers' side, for the `acutrol3000` profile, as data: the exact requests the public
ACL clients send and the manual's own examples (each cited: repository, path and function or line; the
manual's section), in the order a session sends them, and what must come of each on the simulated
ACUTROL3000: understood as profile operations (the reply, one value per query joined by `;`, read by the
driver's own parser), answered as the manual documents, refused (the profile's error reply), or unanswered
(a setting).

tests/protocols/test_turntable_requests.py replays them on a pty. Requests are written without their line
terminator. What the clients send that the simulator does not model is in NOT_SIMULATED, with the reason
and the manual's section, and is answered as an unknown request (on GPIB a real controller answers nothing:
ON_GPIB says why the simulator does). Facts: docs/instruments.md, "`acutrol3000`".
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
    wait_s: float = 0.0  # simulated seconds before the request (a rate reached, a ramp over)


@dataclass(frozen=True)
class Conversation:
    client: str  # owner/repository, or the manual
    licence: str
    rows: tuple[Row, ...]


_IEAV = "python/acutrol3000.py"
_ACR = "acutrol.py"
_FORM = "Acutrol/Form1.cs"
_N = r"-?\d+\.\d+"

CONVERSATIONS: tuple[Conversation, ...] = (
    Conversation("IEAv-EFO/acutrol3000", "none stated", (
        Row("*idn?", f"{_IEAV} __init__ (line 6)", ("identify",)),
        Row(":Interlock:Reset", f"{_IEAV} initialize (lines 52-60); §4.5.6", silent=True),
        Row(":mode:off 1", f"{_IEAV} initialise (lines 52-58)", silent=True),
        Row(":int:close 1", f"{_IEAV} initialise (lines 52-58)", silent=True),
        Row(":interlock? 1", f"{_IEAV} interlock check (line 41)", ("fault",)),
        Row("*stb?", f"{_IEAV} status byte (line 44; 65 is its interlock error)", reply="0"),
        Row(":mode? 1", f"{_IEAV} read_mode (lines 121, 148, 164; it compares Rate/Position, the manual "
            "shows P/R)", reply="O"),
        Row(":read:pos? 1", f"{_IEAV} read_position (lines 24-34)", ("position",)),
        Row(":read:rate? 1", f"{_IEAV} read_rate (lines 24-34)", ("rate",)),
        Row(":read:acc? 1", f"{_IEAV} read_acc; §4.10.1", reply=r"0\.00000"),
        Row(":read:pos? 1;rate? 1;acc? 1", f"{_IEAV} status (line 14); §4.10.1, 4.10.4, 4.10.5",
            reply=rf"{_N};{_N};0\.00000"),
        Row(":mode 1,pos", f"{_IEAV} send_position (lines 143-152); §4.7 (one-command form), §2.7", silent=True),
        Row(":mode? 1", f"{_IEAV} send_position", reply="P"),
        Row(":dem:pos 1,10", f"{_IEAV} send_position", silent=True, axis1_deg=10.0),
        Row(":dem:delta 1,5", f"{_IEAV} send_delta_position (lines 156-172); §4.3.2", silent=True, axis1_deg=15.0),
        Row(":limit:acc? pos,1", f"{_IEAV} limits (lines 83-95); §4.6.2", reply=_N),
        Row(":lim:acc rate,1,8300", f"{_IEAV} set_limits (lines 99-109); §4.6.2", silent=True),
        Row(":lim:rate rate,1,1000", f"{_IEAV} set_limits; §4.6.8", silent=True),
        Row(":lim:rate synt,1,1000", f"{_IEAV} set_limits; §4.6.8 (held and read back only)", silent=True),
        Row(":limit:acc? rate,1", f"{_IEAV} limits; §4.6.2", reply=r"8300\.00000"),
        Row(":limit:rate? synt,1", f"{_IEAV} limits; §4.6.8", reply=r"1000\.00000"),
        Row(":mode:rate 1", f"{_IEAV} stop (lines 72-79); §4.7.5", silent=True),
        Row(":dem:rate 1,10", f"{_IEAV} send_rate's demand; §4.3.6", silent=True),
        Row(":read:pos? 1;rate? 1;acc? 1", f"{_IEAV} status, at rate: the ramp over at 8300 °/s²",
            reply=rf"{_N};10\.00000;0\.00000", wait_s=1.0),
        Row(":mode? 1", f"{_IEAV} read_mode", reply="R"),
        Row(":dem:rate 1,0", f"{_IEAV} stop (lines 72-78, 185-190)", silent=True),
        Row(":read:rate? 1", f"{_IEAV} wait_stop: at rest", reply=r"0\.00000", wait_s=1.0),
        Row(":int:open 1", f"{_IEAV} terminate (line 67); §4.5.5", silent=True),
        Row(":interlock? 1", f"{_IEAV} check_error (line 41): an opened interlock", reply="Open"),
        Row("*stb?", f"{_IEAV} check_error (line 44)", reply="65"),
        Row(":int:close 1", f"{_IEAV} send_rate (line 120); §4.5.1", silent=True),
        Row(":interlock? 1", f"{_IEAV} check_error", ("fault",)),
        Row(":m:p ALL", "examples/routine_example.cfg (a macro file); §2.4 (ALL for a command)", silent=True),
        Row(":mode? 1;:mode? 2;:mode? 3", "§4.7", reply="P;P;P"),
    )),
    Conversation("AcutronicRobotics/acutrol", "MIT", (
        Row(":utility:lockout on", f"{_ACR} ac117.json startup list; §4.14.2", silent=True),
        Row(":interlock:open 1", f"{_ACR} ac117.json startup list; §4.5.5", silent=True),
        Row(":interlock:reset 1", f"{_ACR} ac117.json startup list; §4.5.6 (the axis taken and ignored)",
            silent=True),
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
        Row(":mode:rate 1", f"{_ACR} command_rate; §4.7.5", silent=True),
        Row(":demand:rate 1, 05.730", f"{_ACR} command_rate ('%06.3f'); §4.3.6", silent=True),
        Row(":read:rate 1", f"{_ACR} status, at rate", reply=r"5\.73000", wait_s=5.0),
        Row(":interlock:open 1", f"{_ACR} ac117.json shutdown list: the axis shut down", silent=True),
        Row(":read:rate 1", f"{_ACR} status, at rest", reply=r"0\.00000", wait_s=5.0),
    )),
    Conversation("williamsea/Acutrol", "none stated", (
        Row(":I:R ", f"{_FORM} button_interlock_reset_Click; §4.5.6", silent=True),
        Row(":I:C 1  ", f"{_FORM} Interlock_Close; §4.5.1", silent=True),
        Row(":M:P 1 ", f"{_FORM} SelectMode(P); §4.7.4", silent=True),
        Row(":D:P 1, 10 ", f"{_FORM} CommendParameter(P, 10); §4.3.5", silent=True, axis1_deg=10.0),
        Row(":u:f f ; :R:P 1 ", f"{_FORM} ReadParameter(P); §4.14.1, §4.10 (no '?': ACT2000)", ("position",)),
        Row(":M:R 1 ", f"{_FORM} SelectMode(R); §4.7.5", silent=True),
        Row(":D:R 1, 5 ", f"{_FORM} CommendParameter(R, 5); §4.3.6", silent=True),
        Row(":u:f f ; :R:R 1 ", f"{_FORM} ReadParameter(R)", reply=r"5\.00000", wait_s=5.0),
        Row(":u:f f ; :R:A 1 ", f"{_FORM} ReadParameter(A); §4.10.1", reply=r"0\.00000"),
        Row(":I:O 1  ", f"{_FORM} Interlock_Open; §4.5.5", silent=True),
        Row(":u:f f ; :R:R 1 ", f"{_FORM} ReadParameter(R): the axis shut down, at rest", reply=r"0\.00000",
            wait_s=5.0),
        Row(":interlock? 1", "Table 6 :Interlock? (an opened interlock)", reply="Open"),
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
        Row(":READ:ACC 1", "§4.10.1", reply=r"0\.00000"),
        Row(":R:A 2;R 2;P 2", "§4.10.1 (→ acceleration;rate;position)", reply=rf"0\.00000;{_N};{_N}"),
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
        Row(":DEM:Delta 1,-45.0", "§4.3.2", silent=True, axis1_deg=90.223),
        Row(":DEM:DEL? 2;DEL? 1", "§4.3.2 (→ 1.00000;-45.00000)", reply=r"0\.00000;-45\.00000"),
        Row(":LIM:ACC P,1,1500.0", "§4.6.2", silent=True),
        Row(":LIM:ACC? P,1", "§4.6.2 (→ 1500.0)", reply=r"1500\.00000"),
        Row(":LIM:RATE P,1,120.0", "§4.6.8", silent=True),
        Row(":L:R R,3,100.0;R R,2,10.0", "§4.6.8", silent=True),
        Row(":LIM:RATE? P,1;:L:R? R,3;R? R,2", "§4.6.8 (:LIM:RATE? P,3 → 50.0000)",
            reply=r"120\.00000;100\.00000;10\.00000"),
        Row(":L:R? O,1", "§4.6.8: the rate limit is forced to zero in Off mode", reply=r"0\.00000"),
        Row(":L:R? X,1", "§4.6: no such profiler mode", refused=True),
        Row(":LIM:ACC P,1,0", "§4.6.2: an acceleration limit of zero 'should never be commanded'", refused=True),
        Row(":U:L ON", "§4.14.2", silent=True),
        Row(":U:L?", "§4.14.2 (→ OFF)", reply="ON"),
        Row(":U:F F", "§4.14.1", silent=True),
        Row(":U:F?", "§4.14.1 (→ FLOAT)", reply="FLOAT"),
        Row(":MODE:RATE 3", "§4.7.5", silent=True),
        Row(":M? 3", "§4.7", reply="R"),
        Row(":Mode ALL,Position", "§4.7 (<axis|ALL>,<mode>), §2.4", silent=True),
        Row(":M? 1;:M? 2;:M? 3", "§4.7", reply="P;P;P"),
        Row(":INT:RES;CLOS 1", "§4.5.6", silent=True),
        Row(":MODE:OFF 1", "§4.7.3", silent=True),
        Row(":MODE? 1", "§4.7", reply="O"),
        Row(":I:O 1;O 2;O 3", "§4.5.5", silent=True),
        Row(":INTerlock? 1;:INTerlock? 3", "an opened interlock reads Open (the profile's fault value)",
            reply="Open;Open"),
        Row("*STB?", "§3.10 (an interlock open)", reply="65"),
    )),
)

#: What a real ACUTROL3000 on GPIB does with a command it does not carry out, and why the simulator does not:
#: "unknown commands are ignored and do not generate an SRQ" and a bad device-dependent message (an axis out
#: of range, data of the wrong size) sets bit 2 of the Event Status Register, read by `*ESR?` (TM-8004-C
#: Table 1, §3.3). The simulator answers `ERR …` instead (and, with `acknowledgement: length-prefixed`, an
#: error code block, as §2 says of the other interfaces): the project's driver sends settings unanswered and
#: names a refusal from that line (`error_pattern: ^ERR`), in one reply; silence would leave a refused setting
#: unnoticed until a later `*ESR?`, which the driver does not ask.
ON_GPIB = ("a real controller on GPIB ignores it without a reply (an unknown command), or sets ESR bit 2 (a bad "
           "message); the simulator answers ERR (TM-8004-C Table 1, §3.3)")

_OSC = "no synthesis (sine) mode or oscillator in the simulated motion"
_ILL_FORMED = ("ill-formed: a blank after ':L' ends the header (§2.1, §2.3: a compound header contains no white "
               "space), so ':L' is read with the rest as its arguments; written for an older controller")
_OTHER = "(the same command in another mode)"

#: (request, client, where, why the simulator does not serve it): sent by a public client (or the same
#: command's other modes), understood by a real controller, answered by the simulated one as an unknown
#: request (`ERR unknown command …`; on GPIB a real one answers nothing: ON_GPIB).
NOT_SIMULATED: tuple[tuple[str, str, str, str], ...] = (
    (":mode:synt 1", "IEAv-EFO/acutrol3000", f"{_IEAV} stop (lines 72-78)", f"§4.7.6 Mode:Synthesis: {_OSC}"),
    (":M:S 1", "williamsea/Acutrol", f"{_FORM} SelectMode(S)", f"§4.7.6: {_OSC}"),
    (":mode 1,synt", "IEAv-EFO/acutrol3000", _OTHER, f"§4.7, §4.7.6: {_OSC}"),
    (":dem:osc 1,0,0,0", "IEAv-EFO/acutrol3000", f"{_IEAV} stop; send_oscillation", f"§4.3.4 Demand:Oscillator: "
     f"{_OSC}"),
    (":D:O 1, 2, 0.5, 0", "williamsea/Acutrol", f"{_FORM} CommendSinusoidal", f"§4.3.4: {_OSC}"),
    (":con:osc 1,Enable,2.0,0.1,Pos,Lin", "IEAv-EFO/acutrol3000", f"{_IEAV} set_oscillation (lines 176-182)",
     f"§4.2.19 Configure:Oscillator: {_OSC}"),
    (":con:osc? 1", "IEAv-EFO/acutrol3000", f"{_IEAV} set_oscillation", f"§4.2.19: {_OSC}"),
    (":M:A 1", "williamsea/Acutrol", f"{_FORM} SelectMode(A)", "§4.7.1 Mode:Arate: absolute rate overshoots to "
     "synchronise position; the simulated rate motion has no such profile"),
    (":mode:arate 1", "IEAv-EFO/acutrol3000", _OTHER, "§4.7.1: as above"),
    (":mode 1,arate", "IEAv-EFO/acutrol3000", _OTHER, "§4.7.1: as above"),
    (":mode:track 1", "IEAv-EFO/acutrol3000", _OTHER, "§4.7.7 Mode:Track: no tracking input to follow"),
    (":mode 1,track", "IEAv-EFO/acutrol3000", _OTHER, "§4.7.7: as above"),
    (":D:A 1, 2", "williamsea/Acutrol", f"{_FORM} CommendParameter(A, 2)", "§4.3.1 Demand:Acceleration: no "
     "acceleration-demand mode in the simulated motion (rate mode ramps at its limit)"),
    (":limit:absolute? 1", "IEAv-EFO/acutrol3000", f"{_IEAV} limits (line 87)", "§4.6.1 Limit:Absolute (the "
     "factory limits): jerk, velocity-trip and tracking-error limits the rig config does not hold, and the "
     "query's answer layout is not given"),
    (":u:f f ; :r:o 1", "williamsea/Acutrol", f"{_FORM} ReadOvarParameter", "Table 5 :Read:Ovariable (ACT2000 "
     "output variables): no such variables"),
    (":u:f b", "williamsea/Acutrol", "(the other format of :u:f f)", "§4.14.1 Utility:Format BINary: 32-bit "
     "binary answers are not simulated"),
    (":L :L P 1 -10; :L :H P 1 10", "williamsea/Acutrol", f"{_FORM} SetAllLimits", _ILL_FORMED),
    (":L :R P 1 20", "williamsea/Acutrol", f"{_FORM} SetAllLimits", _ILL_FORMED),
    (":L :A P 1 50", "williamsea/Acutrol", f"{_FORM} SetAllLimits", _ILL_FORMED),
    (":L :R A 1 20", "williamsea/Acutrol", f"{_FORM} SetAllLimits", _ILL_FORMED),
    (":L :V P 1 30", "williamsea/Acutrol", f"{_FORM} SetAllLimits", _ILL_FORMED),
    (":C:W 1, 1082", "williamsea/Acutrol", f"{_FORM} SetupWindows", "Table 5 :Configure:Window: no display "
     "windows"),
    ("u:t 179,179,176,32,152,151,32,50,176,181,181,181", "williamsea/Acutrol", f"{_FORM} button_ECP_Click",
     "Table 5 :Utility:Touch: front-panel touch sequences (Table 8: legacy sequences 'will not function as "
     "expected', §1); no panel"),
    (":u:t 180,177,178,50,32,144,32,176,181,179,50,32,144,32,176,181,181,181", "williamsea/Acutrol",
     f"{_FORM} button_cut_analog_input_Click", "Table 5 :Utility:Touch: as above"),
)
