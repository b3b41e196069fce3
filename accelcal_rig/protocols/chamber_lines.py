"""Chamber controllers that speak ASCII lines (ESPEC, Thermotron, Vötsch/Weiss SIMSERV, Watlow F4T SCPI):
their protocols as data, one profile each (facts and their sources: docs/instruments.md).

Each operation is a command: what to send (a template; `{value}` is a set point in °C), the pattern a good
reply matches in full (named groups carry values: `pv`, `sp`, `low`, `high`, `identity`, `alarm`, `units`,
`humidity`), and the answer a controller gives (a template of the same names, for the simulator generated
from the profile). A command without a reply pattern is sent and not answered (SCPI settings); the
driver then reads back what it set. A reply matching `error_pattern` is the controller refusing; its
`code` group is looked up in `errors` for a meaning a technician can act on.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from accelcal_rig.protocols.line_dialects import Dialect, check, request_pattern, spelled
from accelcal_rig.protocols.line_templates import NUMBER, TemplateCommand, decimals_of, fields_of, regular_expression

#: What a request may name (the set point it writes), with a sample value.
_SEND_SAMPLE: dict[str, object] = {"value": -12.5}
#: What an answer may name: the request's set point, the values replies carry, the request as the controller
#: received it (an echo: ESPEC's `OK:<command>`), the chamber's sensor types and rated maximum (ESPEC's
#: `TYPE?`: the limits may be set within its range, not beyond), and the humidity control's set point (a
#: number, or OFF) and limits (ESPEC's `HUMI?`).
_ANSWER_SAMPLE: dict[str, object] = {**_SEND_SAMPLE, "pv": 0.0, "sp": 0.0, "low": 0.0, "high": 0.0, "identity": "x",
                                     "alarm": "0", "units": "C", "humidity": 0.0, "request": "x", "sensors": "T",
                                     "rated_high": 0.0, "humidity_sp": "OFF", "humidity_high": 0.0,
                                     "humidity_low": 0.0}

Operation = Literal["identify", "read_temperature", "read_setpoint", "write_setpoint", "read_low_limit",
                    "read_high_limit", "power_on", "power_off", "alarm", "units", "humidity", "purge_on",
                    "purge_off"]


class LineCommand(TemplateCommand):
    send_fields = _SEND_SAMPLE
    answer_fields = _ANSWER_SAMPLE


class ChamberLineProtocol(BaseModel):
    """One controller family's line protocol. Optional operations are absent where it has none."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    write_terminator: str = Field("\n", min_length=1, max_length=4)
    read_terminator: str = Field("\n", min_length=1, max_length=4)
    any_line_end: bool = Field(False, description="the controller ends a request at CR, LF or CR LF, whichever "
                               "comes (for the simulator: a client's other terminator answered, not joined to the "
                               "next request); the driver sends write_terminator")
    dialect: Dialect = Field("plain", description="how the controller reads a request: plain text, ESPEC (a "
                             "blank after a comma optional), SIMSERV (numbered commands), SCPI (headers)")
    encoding: Literal["ascii", "latin-1"] = Field("ascii", description="latin-1 where fields are separated by a "
                                                  "byte above 0x7F (SIMSERV's 0xB6)")
    request_prefix: str = Field("", max_length=16, description="sent before every request: an RS-485 address")
    default_port: int | None = Field(None, ge=1, le=65535, description="the controller's TCP port, documented")
    error_pattern: str = Field("(?!)", max_length=256, description="a reply matching it is a refusal; group `code`")
    errors: dict[str, str] = Field({}, description="error code → what it means, for the one-line error")
    unknown_command_answer: str | None = Field(None, max_length=256, description="what the simulator answers to "
                                               "a request it does not know (none: silence)")
    unsupported_answer: str | None = Field(None, max_length=256, description="what the simulator answers to a "
                                           "request the controller has but the simulated one does not model: the "
                                           "controller's own 'not supported' (none: as an unknown request)")
    local_mode_answer: str | None = Field(None, max_length=256, description="what the controller answers to a "
                                          "remote write while its panel locks them (ESPEC: PROTECT ON), for the simulator")
    units_celsius: str = Field("C", max_length=16, description="the `units` reply that means °C")
    alarm_inactive: list[str] = Field(["0"], max_length=64, description="`alarm` replies that mean no alarm "
                                      "(where alarm_bits is not set)")
    alarm_bits: int | None = Field(None, ge=1, le=2**31 - 1, description="where set, the `alarm` reply is a status "
                                   "integer and an alarm is any of these bits set (SIMSERV: 8)")
    identify: LineCommand
    read_temperature: LineCommand
    read_setpoint: LineCommand
    write_setpoint: LineCommand
    read_low_limit: LineCommand | None = None
    read_high_limit: LineCommand | None = None
    power_on: LineCommand | None = None
    power_off: LineCommand | None = None
    alarm: LineCommand | None = None
    units: LineCommand | None = None
    humidity: LineCommand | None = None
    purge_on: LineCommand | None = None
    purge_off: LineCommand | None = None

    _compiles = field_validator("error_pattern")(classmethod(lambda cls, value: regular_expression(value)))

    @model_validator(mode="after")
    def _consistent(self) -> ChamberLineProtocol:
        for operation, group in _CARRIES.items():
            command = self.command(operation)
            if command is not None and (command.reply is None or f"(?P<{group}>" not in command.reply):
                raise ValueError(f"{operation}: the reply pattern must capture ({group})")
        if (self.read_low_limit is None) != (self.read_high_limit is None):
            raise ValueError("read_low_limit and read_high_limit come together")
        if (self.power_on is None) != (self.power_off is None) or (self.purge_on is None) != (self.purge_off is None):
            raise ValueError("an output's on and off commands come together")
        value_fields = fields_of(self.write_setpoint.send)
        if [name for name, _ in value_fields] != ["value"] or decimals_of(self.write_setpoint.send, "value") is None \
                and value_fields[0][1] not in ("", "f", "g"):
            raise ValueError("write_setpoint: the request must name the set point once, as {value} or {value:.Nf}")
        before, _, after = self.write_setpoint.send.partition("{value")
        after = after.partition("}")[2]
        if (before and before[-1] in _NUMBER_CHARACTERS) or (after and after[0] in _NUMBER_CHARACTERS):
            raise ValueError("write_setpoint: the set point must not run into digits or signs around it (the "
                             "controller would read another number)")
        for operation in OPERATIONS:
            command = self.command(operation)
            if command is None:
                continue
            if operation != "write_setpoint" and fields_of(command.send):
                raise ValueError(f"{operation}: only write_setpoint's request carries a value")
            try:
                check(command.send, self.dialect)
            except ValueError as exc:
                raise ValueError(f"{operation}: {exc}") from None
            try:
                (self.request_prefix + command.send + (command.answer or "")).encode(self.encoding)
            except UnicodeEncodeError:
                raise ValueError(f"{operation}: not {self.encoding} text") from None
            if command.send != command.send.strip():
                raise ValueError(f"{operation}: the request {command.send!r} has blanks at either end (lost on "
                                 "the line)")
            if not request_pattern(command.send, self.dialect).fullmatch(self._spelled(command, _SEND_SAMPLE)):
                raise ValueError(f"{operation}: the request {command.send!r} does not read back as itself "
                                 "(no padding or blanks inside a field)")
        self._no_request_taken_for_another()
        return self

    def _no_request_taken_for_another(self) -> None:
        """A controller (and the simulator) tells requests apart by their text: one operation's request must
        not read as an earlier operation's, unless they are the same command (ESPEC's TEMP? carries four)."""
        seen: list[tuple[Operation, LineCommand]] = []
        for operation in OPERATIONS:
            command = self.command(operation)
            if command is None:
                continue
            request = self._spelled(command, _SEND_SAMPLE)
            for earlier, other in seen:
                if other.send != command.send and request_pattern(other.send, self.dialect).fullmatch(request):
                    raise ValueError(f"{operation}: its request {request!r} reads as {earlier}'s")
            seen.append((operation, command))

    @property
    def setpoint_decimals(self) -> int | None:
        """The decimals the set point is written with (`{value:.1f}`: 1, a 0.1 °C step); None: in full."""
        return decimals_of(self.write_setpoint.send, "value")

    def alarm_means_active(self, alarm: str) -> bool:
        """Whether an `alarm` reply means an active alarm (ValueError: not the status integer expected)."""
        if self.alarm_bits is not None:
            return int(alarm) & self.alarm_bits != 0
        return alarm not in self.alarm_inactive

    def _spelled(self, command: LineCommand, fields: dict[str, object]) -> str:
        return spelled(command.send, self.dialect).format(**fields)

    def command(self, operation: Operation) -> LineCommand | None:
        command: LineCommand | None = getattr(self, operation)
        return command

    def request(self, operation: Operation, **fields: object) -> str:
        command = self.command(operation)
        if command is None:
            raise ValueError(f"the profile has no {operation} command")
        return self.request_prefix + self._spelled(command, fields)

    def request_patterns(self) -> list[tuple[Operation, LineCommand, object]]:
        """Every command's request as a pattern of every spelling the controller takes (after the prefix), for a
        simulator; in operation order."""
        return [(operation, command, request_pattern(command.send, self.dialect))
                for operation in OPERATIONS if (command := self.command(operation)) is not None]


#: Characters a number is written with: none may touch the set point's field in a request.
_NUMBER_CHARACTERS = frozenset("0123456789.+-eE")

OPERATIONS: tuple[Operation, ...] = ("identify", "read_temperature", "read_setpoint", "write_setpoint",
                                     "read_low_limit", "read_high_limit", "power_on", "power_off", "alarm",
                                     "units", "humidity", "purge_on", "purge_off")
#: The group each query's reply must capture.
_CARRIES: dict[Operation, str] = {"identify": "identity", "read_temperature": "pv", "read_setpoint": "sp",
                                  "read_low_limit": "low", "read_high_limit": "high", "alarm": "alarm",
                                  "units": "units", "humidity": "humidity"}

_N = NUMBER
#: ESPEC P300 / SCP-220 class (ChamberConnectLibrary `p300.py`): `TEMP?` answers measured, set point, upper,
#: lower; fields are read with float(), so a blank after a comma is taken (py-lab-hal splits on ", ").
_ESPEC_TEMP = LineCommand(send="TEMP?", reply=rf"(?P<pv>{_N}),\s*(?P<sp>{_N}),\s*(?P<high>{_N}),\s*(?P<low>{_N})",
                          answer="{pv:.1f},{sp:.1f},{high:.1f},{low:.1f}")
#: A setting is answered `OK:` and the command as received (EHS manual §1.3; ATWG checks the echo).
_ESPEC_OK = r"OK:.*"
ESPEC_P300 = ChamberLineProtocol(
    dialect="espec", write_terminator="\r\n", read_terminator="\r\n", default_port=10001,
    error_pattern=r"^NA:(?P<code>.*)",
    errors={"CMD ERR": "command not known to this controller", "ADDR ERR": "bad address",
            "CONT NOT READY-1": "the chamber does not support PTCON or humidity",
            "CONT NOT READY-2": "the chamber is not running a program",
            "CONT NOT READY-3": "command not supported by this controller",
            "CONT NOT READY-4": "keys may not be locked while the controller is off",
            "CONT NOT READY-5": "the time signal named is not enabled",
            "DATA NOT READY": "the program named does not exist",
            "PARA ERR": "parameter missing or not recognised",
            "DATA OUT OF RANGE": "value beyond the controller's range",
            "PROTECT ON": "the controller's data protection is on (set on its panel): remote writes are locked",
            "INVALID REQ": "function not supported (the chamber does not have the option)",
            "CHB NOT READY": "the controller could not act on the command"},
    unknown_command_answer="NA:CMD ERR", local_mode_answer="NA:PROTECT ON", unsupported_answer="NA:INVALID REQ",
    identify=LineCommand(send="TYPE?", reply=r"(?P<identity>.+)", answer="{sensors},{identity},{rated_high:.1f}"),
    read_temperature=_ESPEC_TEMP, read_setpoint=_ESPEC_TEMP, read_low_limit=_ESPEC_TEMP, read_high_limit=_ESPEC_TEMP,
    write_setpoint=LineCommand(send="TEMP, S{value:.1f}", reply=_ESPEC_OK, answer="OK:{request}"),
    power_on=LineCommand(send="MODE,CONSTANT", reply=_ESPEC_OK, answer="OK:{request}"),
    power_off=LineCommand(send="MODE,STANDBY", reply=_ESPEC_OK, answer="OK:{request}"),
    alarm=LineCommand(send="ALARM?", reply=r"(?P<alarm>\d+)(,.*)?", answer="{alarm}"),
    humidity=LineCommand(send="HUMI?", reply=rf"(?P<humidity>{_N}),.*",
                         answer="{humidity:.0f},{humidity_sp},{humidity_high:.0f},{humidity_low:.0f}"),
)

#: Thermotron 8800 (8200 class): channel 1 is air temperature, 2 humidity; operations answer `0`. No purge
#: command: its auxiliaries are set eight at a time (`AUXE1,ddd`), which would clobber the others wired there.
#: Its clients end requests with CR LF, CR or LF and no source says which it takes: each ends a request.
THERMOTRON_8800 = ChamberLineProtocol(
    write_terminator="\r", read_terminator="\r\n", default_port=8888, any_line_end=True,
    identify=LineCommand(send="IDEN?", reply=r"(?P<identity>.+)", answer="{identity}"),
    read_temperature=LineCommand(send="PVAR1?", reply=rf"(?P<pv>{_N})", answer="{pv:.2f}"),
    read_setpoint=LineCommand(send="SETP1?", reply=rf"(?P<sp>{_N})", answer="{sp:.2f}"),
    write_setpoint=LineCommand(send="SETP1,{value:.1f}", reply="0", answer="0"),
    power_on=LineCommand(send="RUNM", reply="0", answer="0"),
    power_off=LineCommand(send="STOP", reply="0", answer="0"),
    alarm=LineCommand(send="ALRM1?", reply=r"(?P<alarm>\d+)", answer="{alarm}"),
    units=LineCommand(send="CCHR1?", reply=r"(?P<units>[A-Za-z°]+)", answer="{units}"),
    humidity=LineCommand(send="PVAR2?", reply=rf"(?P<humidity>{_N})", answer="{humidity:.1f}"),
)

#: Vötsch/Weiss SIMSERV: numbered commands, fields separated by ¶ (0xB6), chamber index 1; replies begin
#: with a status, 1 = accepted, and any fields after the value are taken (the clients ignore them).
_S = "\u00b6"
_MORE = f"(?:{_S}.*)?"
SIMSERV = ChamberLineProtocol(
    dialect="simserv", write_terminator="\r", read_terminator="\r\n", encoding="latin-1", default_port=2049,
    error_pattern=r"^(?P<code>-\d+)",
    errors={"-5": "command number not known", "-6": "too few or incorrect parameters",
            "-8": "data could not be read"},
    unknown_command_answer="-5", unsupported_answer="-8",
    identify=LineCommand(send=f"99997{_S}1{_S}1", reply=rf"1{_S}(?P<identity>[^{_S}]*){_MORE}",
                         answer=f"1{_S}{{identity}}"),
    read_temperature=LineCommand(send=f"11004{_S}1{_S}1", reply=rf"1{_S}(?P<pv>{_N}){_MORE}", answer=f"1{_S}{{pv:.1f}}"),
    read_setpoint=LineCommand(send=f"11002{_S}1{_S}1", reply=rf"1{_S}(?P<sp>{_N}){_MORE}", answer=f"1{_S}{{sp:.1f}}"),
    write_setpoint=LineCommand(send=f"11001{_S}1{_S}1{_S}{{value:.1f}}", reply="1", answer="1"),
    read_low_limit=LineCommand(send=f"11007{_S}1{_S}1", reply=rf"1{_S}(?P<low>{_N}){_MORE}", answer=f"1{_S}{{low:.1f}}"),
    read_high_limit=LineCommand(send=f"11009{_S}1{_S}1", reply=rf"1{_S}(?P<high>{_N}){_MORE}",
                                answer=f"1{_S}{{high:.1f}}"),
    power_on=LineCommand(send=f"14001{_S}1{_S}1{_S}1", reply="1", answer="1"),  # digital output 1: the manual run
    power_off=LineCommand(send=f"14001{_S}1{_S}1{_S}0", reply="1", answer="1"),
    alarm=LineCommand(send=f"10012{_S}1", reply=rf"1{_S}(?P<alarm>\d+){_MORE}", answer=f"1{_S}{{alarm}}"),
    alarm_bits=8,  # status 1 idle, +2 running, +4 warnings, +8 alarms
    units=LineCommand(send=f"11023{_S}1{_S}1", reply=rf"1{_S}(?P<units>[A-Za-z°]+){_MORE}", answer=f"1{_S}{{units}}"),
    units_celsius="\u00b0C",
    humidity=LineCommand(send=f"11004{_S}1{_S}2", reply=rf"1{_S}(?P<humidity>{_N}){_MORE}",
                         answer=f"1{_S}{{humidity:.1f}}"),
    purge_on=LineCommand(send=f"14001{_S}1{_S}8{_S}1", reply="1", answer="1"),  # output 8: chamber wiring
    purge_off=LineCommand(send=f"14001{_S}1{_S}8{_S}0", reply="1", answer="1"),
)

#: Watlow F4T over SCPI (TCP port 5025 only): loop 1 is temperature, loop 2 humidity. Headers in the
#: manual's notation (sent as upper-case long forms). Settings are not answered and the F4T has no error
#: queue: a set point is confirmed by reading it back. `*IDN?` answers `Watlow Electric,<part>,<serial>,
#: <software>` (ESPEC's F4T command list); the simulator's part is its identity, its serial 1.
WATLOW_F4T_SCPI = ChamberLineProtocol(
    dialect="scpi", write_terminator="\n", read_terminator="\n", default_port=5025,
    identify=LineCommand(send="*IDN?", reply=r"(?P<identity>.+)", answer="Watlow Electric,{identity},1,simulated"),
    read_temperature=LineCommand(send=":SOURce:CLOop1:PVALue?", reply=rf"(?P<pv>{_N})", answer="{pv:.2f}"),
    read_setpoint=LineCommand(send=":SOURce:CLOop1:SPOint?", reply=rf"(?P<sp>{_N})", answer="{sp:.2f}"),
    write_setpoint=LineCommand(send=":SOURce:CLOop1:SPOint {value:.2f}"),
    units=LineCommand(send=":UNIT:TEMPerature?", reply=r"(?P<units>[A-Z]+)", answer="{units}"),
    humidity=LineCommand(send=":SOURce:CLOop2:PVALue?", reply=rf"(?P<humidity>{_N})", answer="{humidity:.2f}"),
)

LINE_PROFILES: dict[str, ChamberLineProtocol] = {"espec-p300": ESPEC_P300, "thermotron-8800": THERMOTRON_8800,
                                                 "simserv": SIMSERV, "watlow-f4t-scpi": WATLOW_F4T_SCPI}


def line_protocol(profile: str, overrides: dict[str, object] | None = None) -> ChamberLineProtocol:
    """A built-in profile, with any fields the rig config overrides (validated)."""
    return ChamberLineProtocol.model_validate({**LINE_PROFILES[profile].model_dump(), **(overrides or {})})
