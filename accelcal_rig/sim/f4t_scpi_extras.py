"""What a simulated Watlow F4T answers over SCPI beyond its profile: the headers of ESPEC's F4T command list
(PaulNongL/WatlowF4TscpiLibrary `f4t_scpi_cmds/f4t_scpi_commands.ods`, the list ESPEC's WatlowF4T-SCPI-Lib is
written against) that read or set what the simulator holds. Loop 2's set point, each loop's ramp settings,
event outputs 1-7 and the selected profile are held and read back; an output the profile's power command
names (a TestEquity chamber's output 1, by override) is the chamber's run. Settings are unanswered, as every
F4T setting; a header it does not serve (the cascade headers, listed for controllers with cascade control
only; starting a profile: no profile engine) is met with silence, the F4T having no documented error reply."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol
from accelcal_rig.protocols.scpi_headers import read_notation, split_request
from accelcal_rig.sim.controller_extras import UNKNOWN, Answer, Extras, Panel
from accelcal_rig.sim.lab import VirtualLab

LOOPS = (1, 2)  # 1 temperature, 2 humidity
OUTPUTS = range(1, 8)  # "# = outputs 1-7"
PROFILES = range(1, 41)  # ":PROGRAM:NUMBER <value> | 1-40"

#: The headers served, in the manuals' notation (a mnemonic all in capitals where the list gives no short
#: form), `#` a loop or an output: (header, its parameter as a regular expression or None for a query,
#: the method answering or carrying it out).
HEADERS: tuple[tuple[str, str | None, str], ...] = (
    (":SOURce:CLOop#:SPOint?", None, "_setpoint"),  # loop 1's is the profile's own
    (":SOURce:CLOop#:SPOint", r"(?P<value>\S+)", "_set_setpoint"),
    (":SOURce:CLOop#:RRATE?", None, "_ramp_rate"),
    (":SOURce:CLOop#:RTIME?", None, "_ramp_time"),
    (":SOURce:CLOop#:RRATE", r"(?P<value>\S+)", "_set_ramp_rate"),
    (":SOURce:CLOop#:RTIME", r"(?P<value>\S+)", "_set_ramp_time"),
    (":SOURce:CLOop#:RACTION", r"(?i:OFF)", "_ramp_off"),  # STARTUP, SETPOINT, BOTH: ramping not simulated
    (":SOURce:CLOop#:RSCALE", r"(?P<scale>(?i:MINUTES|HOURS))", "_set_ramp_scale"),
    (":SOURce:CLOop#:ERROR?", None, "_input_error"),
    (":OUTPut#:STATe?", None, "_output"),
    (":OUTPut#:STATe", r"(?P<state>(?i:ON|OFF))", "_set_output"),
    (":PROGRAM:NUMBER", r"(?P<number>\d+)", "_select_profile"),
    (":PROGRAM:NAME?", None, "_profile_name"),
)


def _compiled() -> list[tuple[re.Pattern[str], int, str]]:
    """Each header for each loop or output, as every spelling the F4T reads: (pattern, the number, method)."""
    found = []
    for header, parameter, method in HEADERS:
        numbers = (OUTPUTS if header.startswith(":OUTPut") else LOOPS) if "#" in header else (0,)
        for number in numbers:
            head = read_notation(header.replace("#", str(number))).pattern()
            found.append((re.compile(head + (rf"\s+{parameter}" if parameter else "")), number, method))
    return found


_SERVED = _compiled()


def serves(request: str) -> bool:
    """Whether the simulated F4T carries out (or answers) this request beyond its profile."""
    return any(pattern.fullmatch(request.strip()) for pattern, _, _ in _SERVED)


@dataclass
class _Ramp:
    rate: float = 0.0
    time: float = 0.0
    scale: str = "MINUTES"


@dataclass
class F4tSettings:
    """Held and read back; ramping is off and stays off (RACTION OFF), so the rates change nothing."""

    setpoints: dict[int, float] = field(default_factory=lambda: {2: 0.0})  # loop 1's is the lab's
    ramps: dict[int, _Ramp] = field(default_factory=lambda: {loop: _Ramp() for loop in LOOPS})
    outputs_on: set[int] = field(default_factory=set)
    profile: int = 1


class F4tScpiExtras(Extras):
    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        super().__init__(protocol, lab, panel)
        self.settings = F4tSettings()
        power = protocol.power_on.send if protocol.power_on is not None else ""
        named = re.fullmatch(r":?OUTP(?:UT)?(\d):STAT(?:E)? ON", power, re.IGNORECASE)
        #: The output the profile's power command switches (TestEquity: 1), read back as the chamber's run.
        self._power_output = int(named[1]) if named else None

    def answer(self, request: str) -> Answer:
        header, parameters = split_request(request.strip())
        text = f"{header} {parameters}" if parameters else header
        for pattern, number, method in _SERVED:
            match = pattern.fullmatch(text)
            if match is not None:
                served: Answer = getattr(self, method)(number, match)
                return served
        return UNKNOWN

    def _setpoint(self, loop: int, match: re.Match[str]) -> Answer:
        return f"{self.settings.setpoints.get(loop, self._lab.thermal.setpoint_c):.2f}"

    def _set_setpoint(self, loop: int, match: re.Match[str]) -> Answer:
        value = _number(match["value"])
        if value is not None:
            self.settings.setpoints[loop] = value  # loop 2: no humidifier simulated, the air does not follow
        return None

    def _ramp_rate(self, loop: int, match: re.Match[str]) -> Answer:
        return f"{self.settings.ramps[loop].rate:.2f}"

    def _ramp_time(self, loop: int, match: re.Match[str]) -> Answer:
        return f"{self.settings.ramps[loop].time:.2f}"

    def _set_ramp_rate(self, loop: int, match: re.Match[str]) -> Answer:
        value = _number(match["value"])
        if value is not None:
            self.settings.ramps[loop].rate = value
        return None

    def _set_ramp_time(self, loop: int, match: re.Match[str]) -> Answer:
        value = _number(match["value"])
        if value is not None:
            self.settings.ramps[loop].time = value
        return None

    def _ramp_off(self, loop: int, match: re.Match[str]) -> Answer:
        return None  # the simulated controller never ramps: the air follows at the chamber's own rate

    def _set_ramp_scale(self, loop: int, match: re.Match[str]) -> Answer:
        self.settings.ramps[loop].scale = match["scale"].upper()
        return None

    def _input_error(self, loop: int, match: re.Match[str]) -> Answer:
        return "NONE"  # no sensor fault is simulated

    def _output(self, output: int, match: re.Match[str]) -> Answer:
        if output == self._power_output:
            return "ON" if self._lab.thermal.powered else "OFF"
        return "ON" if output in self.settings.outputs_on else "OFF"

    def _set_output(self, output: int, match: re.Match[str]) -> Answer:
        """An output the profile does not name as its power is wired to nothing simulated: held only."""
        if match["state"].upper() == "ON":
            self.settings.outputs_on.add(output)
        else:
            self.settings.outputs_on.discard(output)
        return None

    def _select_profile(self, number: int, match: re.Match[str]) -> Answer:
        if int(match["number"]) in PROFILES:
            self.settings.profile = int(match["number"])
        return None

    def _profile_name(self, number: int, match: re.Match[str]) -> Answer:
        return ""  # no profile is stored: every name is empty (ESPEC's library stops listing at one)


def _number(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None
