"""The requests of public clients that cannot be installed here, as data: per public method (function, or a
C# method behind a button), the exact requests in the order the client sends them, and what the maker
documents as the answer to each, cited. tests/protocols/client_sweep.py replays each method on a new
connection through its recording proxy and reads each reply as the client does (a line; or, the
AcutronicRobotics client, one recv() whose first 8 bytes it cuts off).

No code of these clients is copied: the request texts are facts read from their sources (repository, commit,
path, function), and the documented answers are from the makers' command lists and manuals:

- ESPEC North America's WatlowF4T-SCPI-Lib (MIT), f4tscpi/f4t_interface.py and f4t_class.py at commit
  78be8a50a82d417920464818046ab5d3703b3c1b (on no package index; the fetch tool has no snapshot of it: read
  from the search index). Its command list is the spreadsheet in the same author's
  PaulNongL/WatlowF4TscpiLibrary (f4t_scpi_cmds/f4t_scpi_commands.ods, commit
  78615738ffdee820f04c90841fa2598356024e5d): `F4T list` below. Requests end LF; replies are read to LF with a
  1.5 s timeout (F4T.__init__), an unanswered query reading as 'FAILED' (read_items).
- IEAv-EFO/acutrol3000 (no licence stated), python/acutrol3000.py at commit
  3777621b1cf5a1288e5c2134fa97b6276683518f: module functions over PyVISA GPIB (`GPIB1::1::INSTR`); query()
  reads a reply, write() none. On IEEE-488 "the interface protocol only receives a response if the command
  requests data" (TM-8004-C §2, in doc/ of the same repository): settings unanswered.
- AcutronicRobotics/acutrol (MIT), acutrol.py and ac117.json at commit
  5e9b652eddc1e4c2c664c1c3df7daf553471fefd (Python 2: `<>`): class AcutrolDevice over TCP (port 9888),
  each command followed by '\r\n' and answered, as TM-8004-C §2 says of the interfaces other than IEEE-488
  ("all commands issued to Acutrol will receive a response … an error code and a message length; this is
  prefixed to data"): the client reads one recv(1024), cuts 8 bytes and compares `OK` (ac117.json) or reads a
  number.
- williamsea/Acutrol (no licence stated), Acutrol/Form1.cs at commit
  0f6be385c44abd2ce9e8fa277a4b47f235c98f26: a Windows Forms client over NI VisaNS GPIB (`GPIB0::1::INSTR`),
  each message ending ` \n` (a blank, then LF). The same author's Acutrol_VisualStudio2010 is a later copy.

The ACUTROL3000 simulator serves the profile on a serial line (LF): the GPIB clients' requests are sent with LF
(on GPIB EOI ends a message, "optionally followed by CR and/or LF", TM-8004-C §2.4); the TCP client's with its
own CR LF.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from accelcal_rig.protocols.acl_blocks import PREFIX_BYTES, prefix

_N = r"[-+]?\d+(\.\d+)?([eE][-+]?\d+)?"  # a number as the clients read it (float())


@dataclass(frozen=True)
class Expect:
    """One request as the client sends it (without its terminator) and the answer its maker documents."""

    request: str
    answer: str | None  # a regular expression the reply (terminators cut) must match in full; None: no reply
    source: str  # where the maker documents that answer
    prefixed: bool = False  # the reply starts with an 8-byte prefix the client cuts off (ACL over TCP)
    refusal: bool = False  # the documented answer is the controller's refusal (ESPEC NA:…) in the simulated state

    def check(self, reply: bytes) -> str:
        """'' when the reply is the documented one; else what is wrong with it."""
        text = reply.decode("latin-1")
        if self.answer is None:
            return "" if not text else f"answered {text.strip()!r}; documented: no reply ({self.source})"
        if not text:
            return f"no reply; documented: {self.answer!r} ({self.source})"
        if self.prefixed:  # a response block (protocols/acl_blocks.py): error code 0, then the answer
            found = prefix(reply)
            body = reply[PREFIX_BYTES:].decode("latin-1").strip()
            if found is not None and found[0] == 0 and re.fullmatch(self.answer, body):
                return ""
            if found is not None:
                return f"answered error code {found[0]}, {body!r}; documented: code 0 and {self.answer!r} ({self.source})"
            return f"answered {text.strip()!r}, no prefix (the client reads {text[8:].strip()!r}); documented: an " \
                   f"error code and a length, then {self.answer!r} ({self.source})"
        if not re.fullmatch(self.answer, text.strip()):
            return f"answered {text.strip()!r}; documented: {self.answer!r} ({self.source})"
        return ""


@dataclass(frozen=True)
class Method:
    name: str
    where: str  # path and function (line) in the client's repository
    call: str  # the call the requests are for (its arguments)
    requests: tuple[Expect, ...] = ()
    not_sent: str | None = None  # a public method that sends nothing of its own: why


@dataclass(frozen=True)
class DataClient:
    name: str
    profile: str  # the simulator it is replayed against
    source: str  # repository@commit
    licence: str
    transport: str
    write_terminator: str
    read_terminator: str
    reply_wait_s: float  # how long the replay waits for a reply (the client's own timeout, shortened)
    methods: tuple[Method, ...]
    profile_overrides: tuple[tuple[str, object], ...] = ()  # the profile as that client's rig configures it


# ---------------------------------------------------------------------- ESPEC's F4T SCPI library
_F4T_LIST = "F4T list (PaulNongL/WatlowF4TscpiLibrary f4t_scpi_cmds/f4t_scpi_commands.ods)"
_FLOAT = rf"{_N}"
_IF = "f4tscpi/f4t_interface.py"
_CLS = "f4tscpi/f4t_class.py"


def _f4t_query(request: str, answer: str, row: str) -> Expect:
    return Expect(request, answer, f"{_F4T_LIST}: {row}")


def _f4t_setting(request: str, row: str) -> Expect:
    return Expect(request, None, f"{_F4T_LIST}: {row} (W: a setting, unanswered)")


_IDN = _f4t_query("*IDN?", r"Watlow Electric,[^,]*,\d+,[^,]*", "Identification → Watlow Electric | <string> | "
                  "<integer> | <string>")

F4T_SCPI = DataClient(
    "ESPEC WatlowF4T-SCPI-Lib F4T", "watlow-f4t-scpi",
    "EspecNorthAmerica/WatlowF4T-SCPI-Lib@78be8a50a82d417920464818046ab5d3703b3c1b", "MIT",
    "request lists replayed over TCP through the proxy (the library connects to port 5025 with "
    "socket.create_connection)", "\n", "\n", 0.3, (
        Method("__init__", f"{_CLS} Controller.__init__ (get_id when no id is given)", "F4T(host)", (_IDN,)),
        Method("get_id", f"{_IF} F4T.get_id", "get_id()", (_IDN,)),
        Method("get_units", f"{_IF} F4T.get_units (TempUnits(rsp): C or F)", "get_units()",
               (_f4t_query(":UNIT:TEMPERATURE?", "C|F", "Query Comm. Temperature units → C|F"),)),
        Method("set_units", f"{_IF} F4T.set_units (get_units; its else branch, ':UNITS:TEMPERATURE' + 'C', is "
               "unreachable: get_units returns a TempUnits or raises)", "set_units()",
               (_f4t_query(":UNIT:TEMPERATURE?", "C|F", "Query Comm. Temperature units → C|F"),)),
        Method("get_profiles", f"{_IF} F4T.get_profiles (profiles 1…39, each selected then its name read, until a "
               "name is empty; here the first)", "get_profiles()",
               (_f4t_setting(":PROGRAM:NUMBER 1", "Select a profile (1-40)"),
                _f4t_query(":PROGRAM:NAME?", r".*", "Read selected profile name → <string value>"))),
        Method("select_profile", f"{_IF} F4T.select_profile", "select_profile(1)",
               (_f4t_setting(":PROGRAM:NUMBER 1", "Select a profile (1-40)"),)),
        Method("prog_mode", f"{_IF} F4T.prog_mode (docstring: start, stop, pause, resume)", "prog_mode('START')",
               (_f4t_setting(":PROGRAM:SELECTED:STATE START", "start profile"),)),
        Method("get_pv", f"{_IF} F4T.get_pv (loop 1 temperature, 2 humidity)", "get_pv(1); get_pv(2)",
               (_f4t_query(":SOURCE:CLOOP1:PVALUE?", _FLOAT, "Read Temperature PV (Control loop) → <floating point>"),
                _f4t_query(":SOURCE:CLOOP2:PVALUE?", _FLOAT, "Read Temperature PV (Control loop) → <floating point>"))),
        Method("get_sp", f"{_IF} F4T.get_sp", "get_sp(1); get_sp(2)",
               (_f4t_query(":SOURCE:CLOOP1:SPOINT?", _FLOAT, "Read SP → <floating point value>"),
                _f4t_query(":SOURCE:CLOOP2:SPOINT?", _FLOAT, "Read SP → <floating point value>"))),
        Method("get_cascadeSP", f"{_IF} F4T.get_cascadeSP", "get_cascadeSP()",
               (_f4t_query(":SOURCE:CASCADE1:SPOINT?", _FLOAT, "Read Set Point (Cascade) → <floating point value>; "
                           "listed for controllers WITH cascade control only"),)),
        Method("get_cascadeLoopPV", f"{_IF} F4T.get_cascadeLoopPV (loop true: OUTER, else INNER)",
               "get_cascadeLoopPV(True); get_cascadeLoopPV(False)",
               (_f4t_query(":SOURCE:CASCADE1:OUTER:PVALUE?", _FLOAT, "Read Outer Loop PV (Cascade); cascade only"),
                _f4t_query(":SOURCE:CASCADE1:INNER:PVALUE?", _FLOAT, "Read Inner Loop PV (Cascade); cascade only"))),
        Method("get_cascadeLoopSP", f"{_IF} F4T.get_cascadeLoopSP", "get_cascadeLoopSP(True); get_cascadeLoopSP(False)",
               (_f4t_query(":SOURCE:CASCADE1:OUTER:SPOINT?", _FLOAT, "Read Outer Loop Set Point (Cascade); cascade only"),
                _f4t_query(":SOURCE:CASCADE1:INNER:SPOINT?", _FLOAT, "Read Inner Loop Set Point (Cascade); cascade only"))),
        Method("write_sp", f"{_IF} F4T.write_sp (no leading colon; the value as str(float))", "write_sp(25.0, 1)",
               (_f4t_setting("SOURCE:CLOOP1:SPOINT 25.0", "Write SP"),
                _f4t_query(":SOURCE:CLOOP1:SPOINT?", r"25(\.0+)?", "Read SP (read back: the set point written)"))),
        Method("get_ts", f"{_IF} F4T.get_ts", "get_ts(1)",
               (_f4t_query(":OUTPUT1:STATE?", "OFF|ON", "Query event output state → OFF|ON (outputs 1-7)"),)),
        Method("set_output", f"{_IF} F4T.set_output (reads the state, writes the other)", "set_output(1)",
               (_f4t_query(":OUTPUT1:STATE?", "OFF|ON", "Query event output state → OFF|ON (outputs 1-7)"),
                _f4t_setting(":OUTPUT1:STATE ON", "Set event output on"),
                _f4t_query(":OUTPUT1:STATE?", "ON", "Query event output state (read back)"))),
        Method("get_tsName", f"{_IF} F4T.get_tsName", "get_tsName(1)",
               (Expect(":OUTPUT1:NAME?", r".*", "not in the F4T list: the library's own (an output's name, a string)"),)),
        Method("ramp_mode", f"{_IF} F4T.ramp_mode (docstring: OFF, STARTUP, SETPOINT, BOTH)", "ramp_mode('OFF', 1)",
               (_f4t_setting(":SOURCE:CLOOP1:RACTION OFF", "Set ramping off"),)),
        Method("get_ramp", f"{_IF} F4T.get_ramp (rate: RRATE, else RTIME)", "get_ramp('rate', 1); get_ramp('time', 1)",
               (_f4t_query(":SOURCE:CLOOP1:RRATE?", _FLOAT, "Read ramp rate → <floating point value>"),
                _f4t_query(":SOURCE:CLOOP1:RTIME?", _FLOAT, "Read ramp time → <floating point value>"))),
        Method("set_ramp", f"{_IF} F4T.set_ramp", "set_ramp('rate', 2.0, 1); set_ramp('time', 30, 1)",
               (_f4t_setting(":SOURCE:CLOOP1:RRATE 2.0", "Write ramp rate"),
                _f4t_setting(":SOURCE:CLOOP1:RTIME 30", "Write ramp time"))),
        Method("set_rampScale", f"{_IF} F4T.set_rampScale (RampScale: HOURS, MINUTES)", "set_rampScale('MINUTES', 1)",
               (_f4t_setting(":SOURCE:CLOOP1:RSCALE MINUTES", "Write ramp scale to minutes"),)),
        Method("send_cmd", f"{_CLS} Controller.send_cmd", "send_cmd(cmd)",
               not_sent="the transport primitive: sends what its caller gives it"),
        Method("read_items", f"{_CLS} Controller.read_items", "read_items()", not_sent="reads a reply; sends nothing"),
        Method("clear_buffer", f"{_CLS} Controller.clear_buffer", "clear_buffer()",
               not_sent="reads and drops what is pending; sends nothing"),
        Method("close", f"{_CLS} Controller.close", "close()", not_sent="closes the socket"),
        Method("source_dev", f"{_CLS} Controller.source_dev (classmethod)", "F4T.source_dev(dev)",
               not_sent="builds an object on another's connection; sends nothing"),
    ))

# ---------------------------------------------------------------------- ACUTROL3000 clients
_ACL = "Acutronic TM-8004-C (ACL Programming Manual, IEAv-EFO/acutrol3000 doc/TM-8004-Command Language.pdf)"
_GPIB_SETTING = f"{_ACL} §2: over IEEE-488 a command is answered only if it requests data"
_IEAV = "python/acutrol3000.py"


def _q(request: str, answer: str, section: str) -> Expect:
    return Expect(request, answer, f"{_ACL} {section}")


def _s(request: str, section: str) -> Expect:
    return Expect(request, None, f"{_GPIB_SETTING}; {section}")


_CHECK_ERROR = (_q(":interlock? 1", r"\w+", "Table 6 :Interlock? (the client compares 'Fault')"),
                _q("*stb?", r"\d+", "§3.10 *STB? → <NR1> 0…255 (the client compares 65)"))
_STOP = (_s(":mode:synt 1", "§4.7.6 Mode:Synthesis"), _s(":dem:osc 1,0,0,0", "§4.3.4 Demand:Oscillator"),
         _s(":mode:rate 1", "§4.7.5 Mode:Rate"), _s(":dem:rate 1,0", "§4.3.6 Demand:Rate"))

IEAV = DataClient(
    "IEAv-EFO acutrol3000", "acutrol3000", "IEAv-EFO/acutrol3000@3777621b1cf5a1288e5c2134fa97b6276683518f",
    "none stated", "request lists replayed over the proxy onto the simulator's serial line (the client: PyVISA "
    "GPIB, query() reads a reply, write() none)", "\n", "\n", 0.3, (
        Method("(module)", f"{_IEAV} lines 4-6 (at import)", "import acutrol3000",
               (_q("*idn?", r".+", "§3 *IDN?"),)),
        Method("status", f"{_IEAV} status (line 14)", "status()",
               (_q(":read:pos? 1;rate? 1;acc? 1", rf"{_N};{_N};{_N}", "§4.10.1, 4.10.4, 4.10.5 (Read:Acceleration, "
                   "Position, Rate; ';' compound, §2.2.2)"),)),
        Method("read_pos", f"{_IEAV} read_pos", "read_pos()", (_q(":read:pos? 1", _N, "§4.10.4 Read:Position?"),)),
        Method("read_rate", f"{_IEAV} read_rate (write, then read)", "read_rate()",
               (_q(":read:rate? 1", _N, "§4.10.5 Read:Rate?"),)),
        Method("read_acc", f"{_IEAV} read_acc", "read_acc()", (_q(":read:acc? 1", _N, "§4.10.1 Read:Acceleration?"),)),
        Method("check_error", f"{_IEAV} check_error (lines 39-48)", "check_error()", _CHECK_ERROR),
        Method("initialize", f"{_IEAV} initialize (lines 52-60; then stop())", "initialize()",
               (_s(":Interlock:Reset", "§4.5.6 Interlock:Reset"), _s(":mode:off 1", "§4.7.3 Mode:Off"),
                _s(":int:close 1", "§4.5.1 Interlock:Close"), *_STOP)),
        Method("terminate", f"{_IEAV} terminate (stop(), then lines 66-68)", "terminate()",
               (*_STOP, _s(":int:open 1", "§4.5.5 Interlock:Open"))),
        Method("stop", f"{_IEAV} stop (lines 72-79: send_oscillation(0,0), rate mode, zero rate)", "stop()", _STOP),
        Method("limits", f"{_IEAV} limits (lines 83-95)", "limits()",
               (_q(":limit:absolute? 1", r".+", "§4.6.1 Limit:Absolute?"),
                *(_q(f":limit:{kind}? {mode},1", _N, "§4.6.2 / 4.6.8 Limit:Acceleration? / Limit:Rate?")
                  for kind in ("acc", "rate") for mode in ("pos", "rate", "synt")))),
        Method("set_limits", f"{_IEAV} set_limits (lines 99-109, defaults 8300, 1000)", "set_limits()",
               tuple(_s(f":lim:{kind} {mode},1,{value}", "§4.6.2 / 4.6.8 Limit:Acceleration / Limit:Rate")
                     for kind, value in (("acc", 8300), ("rate", 1000)) for mode in ("pos", "rate", "synt"))),
        Method("send_rate", f"{_IEAV} send_rate (lines 113-128; check_error, then ':int:close 1', then time.sleed: "
               "an AttributeError in the client ends it there)", "send_rate(10)",
               (*_CHECK_ERROR, _s(":int:close 1", "§4.5.1 Interlock:Close"))),
        Method("wait_stop", f"{_IEAV} wait_stop (status() until |rate| <= 0.01)", "wait_stop()",
               (_q(":read:pos? 1;rate? 1;acc? 1", rf"{_N};{_N};{_N}", "§4.10 (as status)"),)),
        Method("send_position", f"{_IEAV} send_position (lines 143-152: ':mode 1,pos' unless ':mode? 1' reads "
               "'Position')", "send_position(10)",
               (*_CHECK_ERROR, _s(":int:close 1", "§4.5.1 Interlock:Close"),
                _q(":mode? 1", "P|R|S|O|A|Position|Rate", "§4.7 Mode[?] (examples answer P, R; the client compares "
                   "'Position')"),
                _s(":mode 1,pos", "§4.7 Mode[?]"), _s(":dem:pos 1,10", "§4.3.5 Demand:Position"))),
        Method("send_delta_position", f"{_IEAV} send_delta_position (lines 156-172)", "send_delta_position(5)",
               (*_CHECK_ERROR, _s(":int:close 1", "§4.5.1 Interlock:Close"),
                _q(":mode? 1", "P|R|S|O|A|Position|Rate", "§4.7 Mode[?]"), _s(":mode 1,pos", "§4.7 Mode[?]"),
                _s(":dem:delta 1,5", "§4.3.2 Demand:DeltaPosition"))),
        Method("set_oscillation", f"{_IEAV} set_oscillation (lines 176-182; its comment: 'Command not working')",
               "set_oscillation()",
               (_s(":con:osc 1,Enable,2.0,0.1,Pos,Lin", "§4.2.19 Configure:Oscillator"),
                _q(":con:osc? 1", r".+", "§4.2.19 Configure:Oscillator?"))),
        Method("send_oscillation", f"{_IEAV} send_oscillation (lines 185-193)", "send_oscillation(10, 1)",
               (_s(":mode:synt 1", "§4.7.6 Mode:Synthesis"), _s(":dem:osc 1,10,1,0", "§4.3.4 Demand:Oscillator"))),
    ))

_ACR = "acutrol.py"
_TCP = f"{_ACL} §2 (all commands answered on interfaces other than IEEE-488, error code and length prefixed) and " \
       "the client: recv(1024)[8:]"


def _ok(request: str) -> Expect:
    return Expect(request, "OK", f"{_TCP}; ac117.json expects 'OK'", prefixed=True)


def _acked(request: str) -> Expect:
    return Expect(request, r".*", f"{_TCP} (the client reads and drops it)", prefixed=True)


ACUTRONIC_ROBOTICS = DataClient(
    "AcutronicRobotics acutrol", "acutrol3000", "AcutronicRobotics/acutrol@5e9b652eddc1e4c2c664c1c3df7daf553471fefd",
    "MIT", "request lists replayed over the proxy onto the simulator's serial line, each ending CR LF as the client "
    "sends it over TCP; its reply read as one recv() whose first 8 bytes it cuts", "\r\n", "\n", 0.3, (
        Method("__init__", f"{_ACR} AcutrolDevice.__init__ (then startup())", "AcutrolDevice(IP, PORT)",
               tuple(_ok(c) for c in (":utility:lockout on", ":interlock:open 1", ":interlock:reset 1",
                                      ":interlock:close 1"))),
        Method("startup", f"{_ACR} AcutrolDevice.startup (ac117.json 'startup')", "startup()",
               tuple(_ok(c) for c in (":utility:lockout on", ":interlock:open 1", ":interlock:reset 1",
                                      ":interlock:close 1"))),
        Method("shutdown", f"{_ACR} AcutrolDevice.shutdown (ac117.json 'shutdown')", "shutdown()",
               (_ok(":mode:off 1"), _ok(":interlock:open 1"))),
        Method("status", f"{_ACR} AcutrolDevice.status (no '?': §4.10 ACT2000 compatibility)", "status()",
               (Expect(":read:rate 1", _N, f"{_TCP}; §4.10.5 Read:Rate", prefixed=True),
                Expect(":read:position 1", _N, f"{_TCP}; §4.10.4 Read:Position", prefixed=True))),
        Method("command_position", f"{_ACR} AcutrolDevice.command_position (not yet in position mode)",
               "command_position(0.5)",
               (_acked(":mode:position 1"), _acked(":demand:position 1, 28.648"))),
        Method("command_rate", f"{_ACR} AcutrolDevice.command_rate (not yet in rate mode)", "command_rate(0.1)",
               (_acked(":mode:rate 1"), _acked(":demand:rate 1, 05.730"))),
        Method("send_command", f"{_ACR} AcutrolDevice.send_command", "send_command(command)",
               not_sent="the transport primitive: sends what its caller gives it"),
        Method("send_command_list", f"{_ACR} AcutrolDevice.send_command_list", "send_command_list(list)",
               not_sent="sends its caller's list (startup and shutdown above are its uses)"),
    ), profile_overrides=(("acknowledgement", "length-prefixed"),))  # a TCP client: every command acknowledged

_FORM = "Acutrol/Form1.cs"


def _w(request: str, section: str) -> Expect:
    """A williamsea message: the client writes ' \\n' after it (a trailing blank)."""
    return Expect(request + " ", None, f"{_GPIB_SETTING}; {section}")


def _r(request: str, answer: str, section: str) -> Expect:
    return Expect(request + " ", answer, f"{_ACL} {section}")


WILLIAMSEA = DataClient(
    "williamsea Acutrol (C#)", "acutrol3000", "williamsea/Acutrol@0f6be385c44abd2ce9e8fa277a4b47f235c98f26",
    "none stated", "request lists replayed over the proxy onto the simulator's serial line (the client: NI VisaNS "
    "GPIB, each message ' \\n'-terminated as it writes it)", "\n", "\n", 0.3, (
        Method("SelectMode", f"{_FORM} SelectMode (':M:'+mode+' 1 \\n': P, R, A, S)", "SelectMode(P); SelectMode(R); "
               "SelectMode(A); SelectMode(S)",
               (_w(":M:P 1", "§4.7.4 Mode:Position"), _w(":M:R 1", "§4.7.5 Mode:Rate"),
                _w(":M:A 1", "§4.7.1 Mode:Arate"), _w(":M:S 1", "§4.7.6 Mode:Synthesis"))),
        Method("ReadParameter", f"{_FORM} ReadParameter (':u:f f ; :R:'+P|R|A+' 1 \\n', then ReadString)",
               "ReadParameter(P); (R); (A)",
               tuple(_r(f":u:f f ; :R:{p} 1", _N, "§4.14.1 Utility:Format FLOat; §4.10 Read (no '?': ACT2000)")
                     for p in ("P", "R", "A"))),
        Method("ReadOvarParameter", f"{_FORM} ReadOvarParameter (called only from commented-out code)",
               "ReadOvarParameter(1)", (_r(":u:f f ; :r:o 1", _N, "§4.14.1; Table 5 :Read:Ovariable"),)),
        Method("CommendParameter", f"{_FORM} CommendParameter (':D:'+P|R|A+' 1, '+text+' \\n')",
               "CommendParameter(P, 10); (R, 5); (A, 2)",
               (_w(":D:P 1, 10", "§4.3.5 Demand:Position"), _w(":D:R 1, 5", "§4.3.6 Demand:Rate"),
                _w(":D:A 1, 2", "§4.3.1 Demand:Acceleration"))),
        Method("CommendSinusoidal", f"{_FORM} CommendSinusoidal", "CommendSinusoidal(2, 0.5, 0)",
               (_w(":D:O 1, 2, 0.5, 0", "§4.3.4 Demand:Oscillator"),)),
        Method("SetAllLimits", f"{_FORM} SetAllLimits (per mode P, R, S; abort A; velocity trip)", "SetAllLimits()",
               (_w(":L :L P 1 -10; :L :H P 1 10", "§4.6.7 / 4.6.6 Limit:LowPosition / HighPosition"),
                _w(":L :R P 1 20", "§4.6.8 Limit:Rate"), _w(":L :A P 1 50", "§4.6.2 Limit:Acceleration"),
                _w(":L :R A 1 20", "§4.6.8 Limit:Rate (abort mode)"), _w(":L :V P 1 30", "§4.6.9 Limit:VelocityTrip"))),
        Method("SetupWindows", f"{_FORM} SetupWindows / button_default_windows_Click (':C:W n, code  \\n')",
               "SetupWindows('1', Estimated Position)", (Expect(":C:W 1, 1082  ", None, f"{_GPIB_SETTING}; Table 5 "
                                                                ":Configure:Window"),)),
        Method("Interlock_Open", f"{_FORM} Interlock_Open", "Interlock_Open()",
               (Expect(":I:O 1  ", None, f"{_GPIB_SETTING}; §4.5.5 Interlock:Open"),)),
        Method("Interlock_Close", f"{_FORM} Interlock_Close", "Interlock_Close()",
               (Expect(":I:C 1  ", None, f"{_GPIB_SETTING}; §4.5.1 Interlock:Close"),)),
        Method("button_interlock_reset_Click", f"{_FORM} button_interlock_reset_Click", "(button)",
               (_w(":I:R", "§4.5.6 Interlock:Reset"),)),
        Method("button_ECP_Click", f"{_FORM} button_ECP_Click (touch sequence, no leading colon)", "(button)",
               (_w("u:t 179,179,176,32,152,151,32,50,176,181,181,181", "Table 5 :Utility:Touch (Table 8: behaves "
                   "differently; legacy touch sequences 'will not function as expected', §1)"),)),
        Method("button_cut_analog_input_Click", f"{_FORM} button_cut_analog_input_Click", "(button)",
               (_w(":u:t 180,177,178,50,32,144,32,176,181,179,50,32,144,32,176,181,181,181", "Table 5 :Utility:Touch (Table 8)"),)),
    ))


# ---------------------------------------------------------------------- F4T SCPI: DAsh0244/te107_control
_TE107 = "src/f4t_control.py"
_TE107_LIST = "te107_control ref/scpi_commands.csv (the F4T SCPI command list the repository ships)"


def _te_query(request: str, answer: str, row: str) -> Expect:
    return Expect(request, answer, f"{_TE107_LIST}: {row}")


def _te_setting(request: str, row: str) -> Expect:
    return Expect(request, None, f"{_TE107_LIST}: {row} (W: a setting, unanswered)")


TE107 = DataClient(
    "DAsh0244 te107_control F4TController", "watlow-f4t-scpi",
    "DAsh0244/te107_control@4052018c37b7e25e260fdd9f9e50a2d8019d8faf", "MIT",
    "request lists replayed over TCP through the proxy (the client: socket.create_connection to port 5025, each "
    "request ending LF, replies read in 10-byte recv()s up to LF)", "\n", "\n", 0.3, (
        Method("__init__", f"{_TE107} Device.__init__ (get_id when no id is given; _clear_buffer only reads)",
               "F4TController(host=...)", (_IDN,)),
        Method("from_other_dev", f"{_TE107} Device.from_other_dev (classmethod)", "F4TController.from_other_dev(dev)",
               not_sent="builds an object on another's connection and id: get_id is not called, nothing sent"),
        Method("send_cmd", f"{_TE107} Device.send_cmd", "send_cmd(cmd)",
               not_sent="the transport primitive: sends what its caller gives it"),
        Method("get_id", f"{_TE107} Device.get_id", "get_id()", (_IDN,)),
        Method("get_profiles", f"{_TE107} F4TController.get_profiles (profiles 1…39 until a name reads empty; here "
               "the first)", "get_profiles()",
               (_te_setting(":PROGRAM:NUMBER 1", "Select a profile, 1-40"),
                _te_query(":PROGRAM:NAME?", r".*", "Read selected profile name → <string value>"))),
        Method("get_units", f"{_TE107} F4TController.get_units (TempUnits(resp))", "get_units()",
               (_te_query(":UNIT:TEMPERATURE?", "C|F", "Query Comm. Temperature units → C|F"),)),
        Method("set_units", f"{_TE107} F4TController.set_units (':UNITS:…', where the list has ':UNIT:…')",
               "set_units()", (Expect(":UNITS:TEMPERATURE C", None, f"{_TE107_LIST}: no such header (Set Comm. "
                                      "Temperature units to C is ':UNIT:TEMPERATURE C'); the F4T documents no "
                                      "error reply"),)),
        Method("set_ramp_scale", f"{_TE107} F4TController.set_ramp_scale (formats the RampScale member itself: "
               "str() of an Enum member)", "set_ramp_scale('MINUTES')",
               (Expect(":SOURCE:CLOOP1:RSCALE RampScale.MINUTES", None, f"{_TE107_LIST}: Write ramp scale takes "
                       "MINUTES or HOURS; no error reply documented"),)),
        Method("set_ramp_rate", f"{_TE107} F4TController.set_ramp_rate", "set_ramp_rate(2.0)",
               (_te_setting(":SOURCE:CLOOP1:RRATE 2.0", "Write ramp rate"),)),
        Method("set_ramp_time", f"{_TE107} F4TController.set_ramp_time", "set_ramp_time(30)",
               (_te_setting(":SOURCE:CLOOP1:RTIME 30", "Read [sic] ramp time, :SOURCE:CLOOP#:RTIME <value>, W"),)),
        Method("select_profile", f"{_TE107} F4TController.select_profile", "select_profile(1)",
               (_te_setting(":PROGRAM:NUMBER 1", "Select a profile, 1-40"),)),
        Method("run_profile", f"{_TE107} F4TController.run_profile", "run_profile()",
               (_te_setting(":PROGRAM:SELECTED:STATE START", "start profile"),)),
        Method("stop_profile", f"{_TE107} F4TController.stop_profile", "stop_profile()",
               (_te_setting(":PROGRAM:SELECTED:STATE STOP", "stop profile"),)),
        Method("get_temperature", f"{_TE107} F4TController.get_temperature", "get_temperature()",
               (_te_query(":SOURCE:CLOOP1:PVALUE?", _FLOAT, "Read Temperature PV (Control loop) → <floating point "
                          "value>"),)),
        Method("set_temperature", f"{_TE107} F4TController.set_temperature (no leading colon)", "set_temperature(30.0)",
               (_te_setting("SOURCE:CLOOP1:SPOINT 30.0", "Write SP"),
                )),
        Method("is_done", f"{_TE107} F4TController.is_done", "is_done(1)",
               (_te_query(":OUTPUT1:STATE?", "OFF|ON", "Query event output state → OFF|ON"),)),
        Method("set_output", f"{_TE107} F4TController.set_output", "set_output(1, 'ON')",
               (_te_setting(":OUTPUT1:STATE ON", "Set event output on (outputs 1-7)"),
                _te_query(":OUTPUT1:STATE?", "ON", "Query event output state (read back)"))),
    ))

# ---------------------------------------------------------------------- SIMSERV: SengerM, IzaakWN
S = "\u00b6"  # SIMSERV's field separator (byte 0xB6)
_SIMSERV_OK = "S!MPAC simserv manual (SengerM's [2], 'Operation manual, Communication protocol S!MPAC simserv', §5 as " \
              "its COMMANDS_DICT cites it; IzaakWN chamber_commands.py err_dict: 1 'Command is accepted and executed')"


def _ss(request: str, answer: str, what: str) -> Expect:
    return Expect(request, answer, f"{_SIMSERV_OK}: {what}")


_SENGER = "VotschTechnikClimateChamber/ClimateChamber.py"
_VALUE = rf"1{S}[^{S}]+(?:{S}.*)?"  # accepted, then the value (the client takes the first field)
_BIT = rf"1{S}[01]"

SENGERM = DataClient(
    "SengerM VotschTechnik ClimateChamber", "simserv",
    "SengerM/VotschTechnik-climate-chamber-Python@202e17204fd8a884a840fbbcd3a574d5170e03ab", "MIT",
    "request lists replayed over TCP through the proxy (the client: a socket to port 2049, each request ending CR, "
    "one recv(512) per reply)", "\r", "\r\n", 0.3, (
        Method("create_command_string", f"{_SENGER} create_command_string (module function)", "(number, *args)",
               not_sent="builds a request's bytes: nothing sent"),
        Method("translate_command_name_to_command_number", f"{_SENGER} translate_command_name_to_command_number "
               "(module function)", "(name)", not_sent="looks a name up in COMMANDS_DICT: nothing sent"),
        Method("__init__", f"{_SENGER} ClimateChamber.__init__", "ClimateChamber(ip, -20, 20)",
               not_sent="connects (port 2049) and sets its own limits: nothing sent"),
        Method("query_command_low_level", f"{_SENGER} ClimateChamber.query_command_low_level",
               "query_command_low_level(number, *args)", not_sent="the transport primitive: sends what it is given"),
        Method("query", f"{_SENGER} ClimateChamber.query", "query(name, *args)",
               not_sent="sends the numbered command its caller names (every use of it is a member below)"),
        Method("serial_number", f"{_SENGER} ClimateChamber.serial_number (property)", "serial_number",
               (_ss(f"99997{S}1{S}3", _VALUE, "GET CHAMBER INFO, item 3: serial number"),)),
        Method("test_system_type", f"{_SENGER} ClimateChamber.test_system_type (property)", "test_system_type",
               (_ss(f"99997{S}1{S}1", _VALUE, "GET CHAMBER INFO, item 1: test system type"),)),
        Method("year_manufactured", f"{_SENGER} ClimateChamber.year_manufactured (property)", "year_manufactured",
               (_ss(f"99997{S}1{S}2", _VALUE, "GET CHAMBER INFO, item 2: year manufactured"),)),
        Method("idn", f"{_SENGER} ClimateChamber.idn (property: test_system_type, serial_number, year_manufactured)",
               "idn", (_ss(f"99997{S}1{S}1", _VALUE, "GET CHAMBER INFO 1"),
                       _ss(f"99997{S}1{S}3", _VALUE, "GET CHAMBER INFO 3"),
                       _ss(f"99997{S}1{S}2", _VALUE, "GET CHAMBER INFO 2"))),
        Method("temperature_measured", f"{_SENGER} ClimateChamber.temperature_measured (property)",
               "temperature_measured", (_ss(f"11004{S}1{S}1", rf"1{S}{_N}", "GET CONTROL_VARIABLE ACTUAL_VALUE"),)),
        Method("temperature_set_point", f"{_SENGER} ClimateChamber.temperature_set_point (property, and its setter "
               "with str(celsius))", "temperature_set_point; temperature_set_point = 15.0",
               (_ss(f"11002{S}1{S}1", rf"1{S}{_N}", "GET CONTROL_VARIABLE SET_POINT"),
                _ss(f"11001{S}1{S}1{S}15.0", "1", "SET CONTROL_VARIABLE SET_POINT"))),
        Method("temperature_min", f"{_SENGER} ClimateChamber.temperature_min (property and setter)",
               "temperature_min", not_sent="the object's own safety limit: nothing sent"),
        Method("temperature_max", f"{_SENGER} ClimateChamber.temperature_max (property and setter)",
               "temperature_max", not_sent="the object's own safety limit: nothing sent"),
        Method("dryer", f"{_SENGER} ClimateChamber.dryer (property, and its setter)", "dryer; dryer = True",
               (_ss(f"14003{S}1{S}8", _BIT, "GET DIGITAL_OUT VALUE 8 (the dryer)"),
                _ss(f"14001{S}1{S}8{S}1", "1", "SET DIGITAL_OUT VALUE 8"))),
        Method("compressed_air", f"{_SENGER} ClimateChamber.compressed_air (property, and its setter)",
               "compressed_air; compressed_air = True",
               (_ss(f"14003{S}1{S}7", _BIT, "GET DIGITAL_OUT VALUE 7 (compressed air)"),
                _ss(f"14001{S}1{S}7{S}1", "1", "SET DIGITAL_OUT VALUE 7"))),
        Method("start", f"{_SENGER} ClimateChamber.start", "start()",
               (_ss(f"14001{S}1{S}1{S}1", "1", "START MANUAL_MODE 1, 1"),)),
        Method("is_running", f"{_SENGER} ClimateChamber.is_running (property)", "is_running",
               (_ss(f"14003{S}1{S}1", _BIT, "GET DIGITAL_OUT VALUE 1"),)),
        Method("stop", f"{_SENGER} ClimateChamber.stop", "stop()",
               (_ss(f"14001{S}1{S}1{S}0", "1", "START MANUAL_MODE 1, 0"),)),
    ))

_IZ = "chamber_commands.py"
_GUI = "a Tk dialog asks first"

IZAAKWN = DataClient(
    "IzaakWN ClimateChamberMonitor chamber_commands", "simserv",
    "IzaakWN/ClimateChamberMonitor@858ca67f8fbf2f89cf5b2d85955ca76395e694f4", "none stated",
    "request lists replayed over TCP through the proxy (the client, Python 2: a socket to port 2049, each request "
    "ending CR, one recv(512) per reply); the module's functions and its ClimateChamber socket class", "\r", "\r\n",
    0.3, (
        Method("getTemp", f"{_IZ} getTemp (and ClimateChamber.getTemp)", "getTemp(c)",
               (_ss(f"11004{S}1{S}1", rf"1{S}{_N}", "GET CTRL_VAR VAL"),)),
        Method("getSetp", f"{_IZ} getSetp (and ClimateChamber.getSetp)", "getSetp(c)",
               (_ss(f"11002{S}1{S}1", rf"1{S}{_N}", "GET CTRL_VAR SETPOINT"),)),
        Method("getAir", f"{_IZ} getAir (and ClimateChamber.getAir)", "getAir(c)",
               (_ss(f"14003{S}1{S}7", _BIT, "GET DIGI_OUT VAL 7"),)),
        Method("getDryer", f"{_IZ} getDryer (and ClimateChamber.getDryer)", "getDryer(c)",
               (_ss(f"14003{S}1{S}8", _BIT, "GET DIGI_OUT VAL 8"),)),
        Method("getDewp", f"{_IZ} getDewp", "getDewp(c)", not_sent="returns 18.0: nothing sent"),
        Method("startRun", f"{_IZ} startRun (and ClimateChamber.startRun)", "startRun(c)",
               not_sent="its lambda uses a global `client` the module never defines (NameError before sending); "
               "what it means to send, START MANUAL 1,1, run_manual.py sends (maker_requests.SIMSERV)"),
        Method("stopRun", f"{_IZ} stopRun (and ClimateChamber.stopRun)", "stopRun(c)",
               not_sent="as startRun: a global `client` never defined"),
        Method("disconnect", f"{_IZ} ClimateChamber.disconnect", "c.disconnect()", not_sent="closes the socket"),
        Method("sendSimServCmd", f"{_IZ} sendSimServCmd (and ClimateChamber.sendSimServCmd)", "sendSimServCmd(c, s)",
               not_sent="the transport primitive: sends the command its caller names"),
        Method("createSimServCmdFromString", f"{_IZ} createSimServCmdFromString", "(cmdstr, args)",
               not_sent="builds a request: nothing sent"),
        Method("ceateSimServCmd", f"{_IZ} ceateSimServCmd", "(cmdID, args)", not_sent="builds a request: nothing sent"),
        Method("unpackSimServData", f"{_IZ} unpackSimServData", "(data)", not_sent="parses a reply: nothing sent"),
        Method("connectClimateChamber", f"{_IZ} connectClimateChamber", "connectClimateChamber(ip)",
               not_sent="connects (port 2049): nothing sent"),
        Method("forceWarmUp", f"{_IZ} forceWarmUp (and ClimateChamber.forceWarmUp; no program running: STOP PRGM "
               "not sent)", "forceWarmUp(c)",
               (_ss(f"19210{S}1", r"1" + S + r"\d+", "GET PRGM STATUS (0: not running)"),
                _ss(f"11001{S}1{S}1{S}24", "1", "SET CTRL_VAR SETPOINT"),
                _ss(f"11068{S}1{S}1{S}3", "1", "SET GRAD_UP VAL"),
                _ss(f"11072{S}1{S}1{S}3", "1", "SET GRAD_DWN VAL"),
                _ss(f"14001{S}1{S}7{S}1", "1", "SET DIGI_OUT VAL 7 (air)"),
                _ss(f"14001{S}1{S}8{S}1", "1", "SET DIGI_OUT VAL 8 (dryer)"),
                _ss(f"14001{S}1{S}1{S}1", "1", "START MANUAL 1, 1"))),
        Method("forceWarmUpEvent", f"{_IZ} forceWarmUpEvent", "forceWarmUpEvent(c)",
               not_sent=f"{_GUI}, then forceWarmUp's requests (above)"),
        Method("stopClimateChamber", f"{_IZ} stopClimateChamber (and ClimateChamber.stop; no program running)",
               "stopClimateChamber(c)",
               (_ss(f"19210{S}1", r"1" + S + r"\d+", "GET PRGM STATUS"),
                _ss(f"11004{S}1{S}1", rf"1{S}{_N}", "GET CTRL_VAR VAL"),
                _ss(f"14001{S}1{S}1{S}0", "1", "START MANUAL 1, 0"))),
        Method("stopClimateChamberEvent", f"{_IZ} stopClimateChamberEvent", "stopClimateChamberEvent(c)",
               (_ss(f"19210{S}1", r"1" + S + r"\d+", "GET PRGM STATUS (then a Tk dialog asks; stopClimateChamber's "
                    "requests above)"),)),
        Method("checkActiveWarnings", f"{_IZ} checkActiveWarnings (no message: the loop sends nothing)",
               "checkActiveWarnings(c)", (_ss(f"17002{S}1", r"1" + S + r"\d+", "GET MSG NUM"),)),
        Method("checkInterlock", f"{_IZ} checkInterlock", "checkInterlock(c, temp, dewp)",
               not_sent="compares its arguments; only below the dew point + 5 °C does it call forceWarmUp (above)"),
        Method("getActiveWarnings", f"{_IZ} getActiveWarnings (no message)", "getActiveWarnings(c)",
               (_ss(f"17002{S}1", r"1" + S + r"\d+", "GET MSG NUM"),)),
        Method("openActiveWarnings", f"{_IZ} openActiveWarnings (then getActiveWarnings; a Tk dialog for any)",
               "openActiveWarnings(c)",
               (_ss(f"17002{S}1", r"1" + S + r"\d+", "GET MSG NUM"), _ss(f"17002{S}1", r"1" + S + r"\d+",
                                                                          "GET MSG NUM"))),
        Method("getRunStatus", f"{_IZ} getRunStatus (no program: then the chamber's status)", "getRunStatus(c)",
               (_ss(f"19204{S}1", r"1" + S + r"\d+", "GET PRGM NUM"),
                _ss(f"10012{S}1", r"1" + S + r"\d+", "GET CHAMBER STATUS (1: not running, 3: running)"))),
    ))

# ---------------------------------------------------------------------- ESPEC P300 class: ATWG, vincesum
_ESPEC_OK = "ESPEC: a setting is answered OK:<the command as received> (EHS manual §1.3 as maker_requests.py cites " \
            "it; ChamberConnectLibrary especinteract.py reads OK:/NA:)"
_ESPEC_READ = "ChamberConnectLibrary p300.py (the reply formats its parser reads)"
_TEMP = rf"{_N},{_N},{_N},{_N}"
_HUMI = r"[^,]*,[^,]*,[^,]*,[^,]*"


def _ok_echo(request: str, sent: str | None = None) -> Expect:
    """A P300 setting: answered OK: and the command as received (without the RS-485 address)."""
    return Expect(request, re.escape("OK:" + (sent if sent is not None else request)), _ESPEC_OK)


def _refused(request: str, reply: str, why: str) -> Expect:
    return Expect(request, re.escape(reply), f"ChamberConnectLibrary especinteract.py ERROR_DESCIPTIONS: {why}",
                  refusal=True)


_ATWG = "ATWG/driver/espec/sh641.py"
ATWG = DataClient(
    "akaeba ATWG especShSu", "espec-p300", "akaeba/ATWG@65783bbdb6243136ef9133445d31b32e769b3023",
    "GPL-3.0 (facts only: the requests, read from the source; no code copied)",
    "request lists replayed over TCP through the proxy (the client: RS-232 with pyserial, each request ending CR LF "
    "(sh641Const.MSC_LINE_END), replies read byte by byte to CR LF)", "\r\n", "\r\n", 0.3, (
        Method("open", f"{_ATWG} especShSu.open (TYPE?, then its SH-641's own ID, sh641Const.RSP_CH_ID, must be in "
               "the reply)", "open()",
               (Expect("TYPE?", r"T,T,[^,]+,[-\d.]+", f"{_ESPEC_READ} read_type: drybulb,wetbulb,controller,max "
                       "temperature"),)),
        Method("close", f"{_ATWG} especShSu.close", "close()", not_sent="closes the serial port"),
        Method("write", f"{_ATWG} especShSu.write", "write(msg)",
               not_sent="the transport primitive: sends what its caller gives it"),
        Method("read", f"{_ATWG} especShSu.read", "read()", not_sent="reads a reply; sends nothing"),
        Method("parse", f"{_ATWG} especShSu.parse", "parse(msg)", not_sent="parses a reply text: sends nothing"),
        Method("is_numeric", f"{_ATWG} especShSu.is_numeric", "is_numeric(msg)", not_sent="a text check"),
        Method("get_clima", f"{_ATWG} especShSu.get_clima", "get_clima()",
               (Expect("TEMP?", _TEMP, f"{_ESPEC_READ} read_temp: measured,set point,upper,lower"),
                Expect("HUMI?", _HUMI, f"{_ESPEC_READ} read_humi: measured,set point,upper,lower"))),
        Method("set_clima", f"{_ATWG} especShSu.set_clima (one decimal: MSC_TEMP_RESOLUTION 0.1)",
               "set_clima({'temperature': 25.0})", (_ok_echo("TEMP,S25.0"),)),
        Method("set_power", f"{_ATWG} especShSu.set_power (default OFF; ON)", "set_power(); set_power('ON')",
               (_ok_echo("POWER,OFF"), _ok_echo("POWER,ON"))),
        Method("set_mode", f"{_ATWG} especShSu.set_mode (default STANDBY; CONSTANT, OFF)",
               "set_mode(); set_mode('CONSTANT'); set_mode('OFF')",
               (_ok_echo("MODE,STANDBY"), _ok_echo("MODE,CONSTANT"), _ok_echo("MODE,OFF"))),
        Method("start", f"{_ATWG} especShSu.start (a temperature given: set_clima, set_power ON, set_mode CONSTANT)",
               "start(30.0)", (_ok_echo("TEMP,S30.0"), _ok_echo("POWER,ON"), _ok_echo("MODE,CONSTANT"))),
        Method("stop", f"{_ATWG} especShSu.stop", "stop()", (_ok_echo("MODE,STANDBY"), _ok_echo("POWER,OFF"))),
        Method("info", f"{_ATWG} especShSu.info", "info()", not_sent="returns its constants: nothing sent"),
    ))

_VS = "src/ESPEC.py"
_VS_NOADDR = "sent without the RS-485 address the rest of the class puts in front ('1,'): addressed to no " \
             "controller on the bus, so none answers (inferred from the address scheme, ChamberConnectLibrary " \
             "especinteract.py; not stated by ESPEC)"
_TASKS = "keeps its own task list: nothing sent"


def _vs(request: str) -> str:
    return "1," + request


VINCESUM = DataClient(
    "vincesum ESPEC-Temperature-Control-UI SH241", "espec-p300",
    "vincesum/ESPEC-Temperature-Control-UI@c8d7f761a865857041af6a64e4079ccee765d491", "none stated",
    "request lists replayed over TCP through the proxy onto a simulated controller at RS-485 address 1 (the "
    "client: pyserial through its UARTMaster, each request ending CR LF, replies read with readline())",
    "\r\n", "\r\n", 0.3, (
        Method("__init__", f"{_VS} SH241.__init__", "SH241()", not_sent="lists the FTDI devices: nothing sent"),
        *(Method(name, f"{_VS} SH241.{name} (OpenChannel: the port opened, then SetModeStandby; a thread then "
                 "sends TEMP? every 3 s, tempCheckerLoop)", f"{name}()", (_ok_echo(_vs("MODE,STANDBY"),
                                                                          "MODE,STANDBY"),))
          for name in ("SetRS485", "SetRS232", "OpenChannel")),
        Method("GetType", f"{_VS} SH241.GetType", "GetType()",
               (Expect(_vs("TYPE?"), r"T,(T,)?[^,]+,[-\d.]+", f"{_ESPEC_READ} read_type"),)),
        Method("GetMode", f"{_VS} SH241.GetMode", "GetMode()",
               (Expect(_vs("MODE?"), "OFF|STANDBY|CONSTANT|RUN", f"{_ESPEC_READ} read_mode"),)),
        Method("GetCondition", f"{_VS} SH241.GetCondition", "GetCondition()",
               (Expect(_vs("MON?"), rf"{_N},[^,]*,(OFF|STANDBY|CONSTANT|RUN),\d+", f"{_ESPEC_READ} read_mon"),)),
        Method("GetTemp", f"{_VS} SH241.GetTemp", "GetTemp()",
               (Expect(_vs("TEMP?"), _TEMP, f"{_ESPEC_READ} read_temp"),)),
        Method("GetTempSilent", f"{_VS} SH241.GetTempSilent (also tempCheckerLoop's; it purges the input after "
               "writing, so it may drop the reply it then reads)", "GetTempSilent()",
               (Expect(_vs("TEMP?"), _TEMP, f"{_ESPEC_READ} read_temp"),)),
        Method("SetPowerOn", f"{_VS} SH241.SetPowerOn", "SetPowerOn()", (_ok_echo(_vs("POWER,ON"), "POWER,ON"),)),
        Method("SetPowerOff", f"{_VS} SH241.SetPowerOff", "SetPowerOff()",
               (_ok_echo(_vs("POWER,OFF"), "POWER,OFF"),)),
        Method("SetTemp", f"{_VS} SH241.SetTemp ('%.1f')", "SetTemp(25.0)",
               (_ok_echo(_vs("TEMP,S25.0"), "TEMP,S25.0"),)),
        Method("SetHighTemp", f"{_VS} SH241.SetHighTemp", "SetHighTemp(100.0)",
               (_ok_echo(_vs("TEMP,H100.0"), "TEMP,H100.0"),)),
        Method("SetLowTemp", f"{_VS} SH241.SetLowTemp", "SetLowTemp(-40.0)",
               (_ok_echo(_vs("TEMP,L-40.0"), "TEMP,L-40.0"),)),
        Method("SetHumid", f"{_VS} SH241.SetHumid ('%i')", "SetHumid(50)", (_ok_echo(_vs("HUMI,S50"), "HUMI,S50"),)),
        Method("SetModeOff", f"{_VS} SH241.SetModeOff", "SetModeOff()", (_ok_echo(_vs("MODE,OFF"), "MODE,OFF"),)),
        Method("SetModeStandby", f"{_VS} SH241.SetModeStandby", "SetModeStandby()",
               (_ok_echo(_vs("MODE,STANDBY"), "MODE,STANDBY"),)),
        Method("SetModeConstant", f"{_VS} SH241.SetModeConstant", "SetModeConstant()",
               (_ok_echo(_vs("MODE,CONSTANT"), "MODE,CONSTANT"),)),
        Method("SetModeProgram", f"{_VS} SH241.SetModeProgram ('MODE,RUN 1', a blank before the program number)",
               "SetModeProgram()", (_refused(_vs("MODE,RUN 1"), "NA:DATA NOT READY", "'DATA NOT READY': 'Specified "
                                             "program does not exist' (none stored; for MODE,RUN1, the P300's "
                                             "form)"),)),
        Method("ProgramWrite", f"{_VS} SH241.ProgramWrite (default program; its first block addressed, then "
               "ProgramErase, then a second block without the address, then PRGM DATA?)", "ProgramWrite()",
               (Expect(_vs("PRGM DATA WRITE,PGM:1,EDIT START"), r"OK:.*", _ESPEC_OK),
                Expect(_vs("PRGM DATA WRITE,PGM:1,STEP1,TEMP30.0,TRAMPON,TIME00:01,"), r"OK:.*", _ESPEC_OK),
                Expect(_vs("PRGM DATA WRITE,PGM:1,COUNT,(1.1.1)"), r"OK:.*", _ESPEC_OK),
                Expect(_vs("PRGM DATA WRITE,PGM:1,END,HOLD"), r"OK:.*", _ESPEC_OK),
                Expect(_vs("PRGM DATA WRITE,PGM:1,EDIT END"), r"OK:.*", _ESPEC_OK),
                Expect(_vs("PRGM ERASE,PGM:1"), r"OK:.*", _ESPEC_OK),
                Expect("PRGM DATA WRITE, PGM:1, EDIT START", None, _VS_NOADDR),
                Expect("PRGM DATA WRITE, PGM:1, STEP1, TEMP12.0, TRAMPOFF, TIME02:40", None, _VS_NOADDR),
                Expect("PRGM DATA WRITE, PGM:1, EDIT END", None, _VS_NOADDR),
                Expect("PRGM DATA?", None, _VS_NOADDR))),
        Method("ProgramErase", f"{_VS} SH241.ProgramErase", "ProgramErase()",
               (Expect(_vs("PRGM ERASE,PGM:1"), r"OK:.*", _ESPEC_OK),)),
        Method("ProgramAdvance", f"{_VS} SH241.ProgramAdvance (no program running)", "ProgramAdvance()",
               (_refused(_vs("PRGM,ADVANCE"), "NA:CONT NOT READY-2", "'CONT NOT READY-2': 'Chamber is not running "
                         "a program'"),)),
        Method("ProgramEnd", f"{_VS} SH241.ProgramEnd (no program running)", "ProgramEnd()",
               (_refused(_vs("PRGM,END,HOLD"), "NA:CONT NOT READY-2", "'CONT NOT READY-2': 'Chamber is not running "
                         "a program'"),)),
        *(Method(name, f"{_VS} SH241.{name}", f"{name}(...)", not_sent=_TASKS)
          for name in ("AddTask", "AddCycle", "AddIdle", "WaitTillDateTime", "deleteTask", "PrintTaskList")),
        Method("stopTask", f"{_VS} SH241.stopTask (SetModeStandby, and again when the list is empty)", "stopTask()",
               (_ok_echo(_vs("MODE,STANDBY"), "MODE,STANDBY"), _ok_echo(_vs("MODE,STANDBY"), "MODE,STANDBY"))),
        *(Method(name, f"{_VS} SH241.{name} (an empty task list: SetModeStandby)", f"{name}()",
                 (_ok_echo(_vs("MODE,STANDBY"), "MODE,STANDBY"),)) for name in ("startNextTask", "startTask")),
        Method("startCycle", f"{_VS} SH241.startCycle (state 0: startTemperatureSoak(temp1); then a 3 s timer that "
               "sends nothing)", "startCycle(1, 1, 25.0, 30.0, 0, 1, 0)",
               (_ok_echo(_vs("TEMP,S25.0"), "TEMP,S25.0"), _ok_echo(_vs("MODE,CONSTANT"), "MODE,CONSTANT"))),
        Method("tempCheckerLoop", f"{_VS} SH241.tempCheckerLoop (GetTempSilent every 3 s, for ever; here once)",
               "tempCheckerLoop()", (Expect(_vs("TEMP?"), _TEMP, f"{_ESPEC_READ} read_temp"),)),
        Method("temperatureQuerySchedule", f"{_VS} SH241.temperatureQuerySchedule", "(target, seconds)",
               not_sent="starts a timer for checkTempCallback: nothing sent"),
        Method("checkTempCallback", f"{_VS} SH241.checkTempCallback", "(target, seconds)",
               not_sent="compares the temperature tempCheckerLoop last read: nothing sent"),
        Method("startTemperatureSoak", f"{_VS} SH241.startTemperatureSoak", "startTemperatureSoak(25.0, 60)",
               (_ok_echo(_vs("TEMP,S25.0"), "TEMP,S25.0"), _ok_echo(_vs("MODE,CONSTANT"), "MODE,CONSTANT"))),
        Method("returnToAmbient", f"{_VS} SH241.returnToAmbient", "returnToAmbient()",
               not_sent="calls self.setTemp, which the class does not have (SetTemp): AttributeError before sending"),
        Method("CloseChannel", f"{_VS} SH241.CloseChannel", "CloseChannel()", not_sent="closes the port"),
    ), profile_overrides=(("request_prefix", "1,"),))

DATA_CLIENTS: tuple[DataClient, ...] = (F4T_SCPI, IEAV, ACUTRONIC_ROBOTICS, WILLIAMSEA, TE107, SENGERM, IZAAKWN,
                                        ATWG, VINCESUM)
