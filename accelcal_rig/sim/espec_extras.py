"""What a simulated ESPEC P300 / SCP-220 controller answers beyond its profile (ChamberConnectLibrary's
`p300.py` and `espec.py`, ATWG, espec_pr3j, syndesi's SH-242 driver): its state queries answered from the
lab and its panel (sim/espec_panel.py), its settings answered `OK:<command as received>` and carried out,
and what the simulated chamber does not have refused with the code ESPEC's error table gives for that
state: no product temperature control (`CONT NOT READY-1`), no program running (`-2`), no program or timer
stored (`DATA NOT READY`), a parameter missing (`PARA ERR`), a value beyond the range (`DATA OUT OF RANGE`).
The program editor, timers, remote programs, heater outputs and service requests are not simulated: the
profile's `unsupported_answer` (`NA:INVALID REQ`, "unsupported function … this chamber does not have the
necessary options"). Which code each request gets is inferred from the error table's meanings where no
source states it per command (docs/instruments.md)."""

from __future__ import annotations

import ipaddress
import re
from datetime import date, datetime, time

from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol, Operation
from accelcal_rig.sim.controller_calendar import ControllerCalendar
from accelcal_rig.sim.controller_extras import UNKNOWN, UNSUPPORTED, Answer, Extras, Panel
from accelcal_rig.sim.espec_panel import (
    AUTOMATIC_REFRIGERATION,
    DISPLAY_ROM_VERSION,
    HUMIDITY_RANGE_PCT,
    RELAYS,
    ROM_VERSION,
    EspecSettings,
    counted,
)
from accelcal_rig.sim.lab import VirtualLab

NO_PTCON = "NA:CONT NOT READY-1"  # "chamber does not support PTCON/humidity"
NOT_RUNNING = "NA:CONT NOT READY-2"  # "chamber is not running a program"
KEYS_WHILE_OFF = "NA:CONT NOT READY-4"  # "keys may not be locked while the controller is off"
NO_DATA = "NA:DATA NOT READY"  # "specified program does not exist" (syndesi: "specified data does not exist")
PARAMETER = "NA:PARA ERR"  # "parameter missing or unrecognizable"
OUT_OF_RANGE = "NA:DATA OUT OF RANGE"  # "data not within valid range"
NOT_EDITING = "NA:PRGM WRITE ERR-2"  # "not in program edit/overwrite mode"
EDIT_NOT_ALLOWED = "NA:PRGM WRITE ERR-3"  # "edit request not allowed not in edit mode"

_N = r"[-+]?\d+(?:\.\d*)?"
#: `S<set point> H<upper> L<lower>`, any of them, a blank optional before each number (espec_pr3j: `H 100.0`).
_LIMITS = rf"(?:S ?(?P<s>{_N}|OFF))? ?(?:H ?(?P<h>{_N}))? ?(?:L ?(?P<l>{_N}))?"
_PROGRAM = r"R[AO]M:\d+"


class EspecExtras(Extras):
    """ESPEC P300/SCP-220: the controller is OFF, in STANDBY (on, not conditioning) or CONSTANT (conditioning);
    a temperature-only chamber (a profile without `humidity`) answers `TYPE?` with three fields, `MON?` with
    an empty humidity field and any humidity request with `NA:CONT NOT READY-1`. No program, timer or
    product temperature control is simulated."""

    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        super().__init__(protocol, lab, panel)
        self._controller_on = True
        self.settings = EspecSettings()
        self.calendar = ControllerCalendar(lab.clock)

    def _humidity(self) -> bool:
        return self._protocol.humidity is not None

    def _mode(self) -> str:
        if self._lab.thermal.powered:
            return "CONSTANT"
        return "STANDBY" if self._controller_on else "OFF"

    def values(self) -> dict[str, object]:
        humidity = self.settings.humidity
        return {"sensors": "T,T" if self._humidity() else "T", "alarm": str(self._panel.alarms),
                "humidity_sp": humidity.setpoint_field(), "humidity_high": humidity.high_pct,
                "humidity_low": humidity.low_pct}

    def carried_out(self, operation: Operation) -> None:
        if operation in ("power_on", "power_off"):
            self._controller_on = True  # CONSTANT and STANDBY both leave the controller on

    def answer(self, request: str) -> Answer:
        command = request.replace(", ", ",").upper()
        for pattern, action, setting in REQUESTS:
            match = pattern.fullmatch(command)
            if match is None:
                continue
            if setting and self._panel.local_mode and self._protocol.local_mode_answer is not None:
                return self._protocol.local_mode_answer
            if action.startswith("NA:"):
                return action
            served: Answer = getattr(self, action)(match, request)
            return served
        return UNKNOWN

    # ------------------------------------------------------------------ monitoring
    def _mon(self, match: re.Match[str], request: str) -> Answer:
        humidity = f"{self._lab.chamber_humidity_pct():.0f}" if self._humidity() else ""
        return f"{self._lab.chamber_reading_c():.1f},{humidity},{self._mode()},{self._panel.alarms}"

    def _mode_answer(self, match: re.Match[str], request: str) -> Answer:
        return self._mode()  # no program runs here, so DETAIL has nothing to add

    def _rom(self, match: re.Match[str], request: str) -> Answer:
        return DISPLAY_ROM_VERSION if match["display"] else ROM_VERSION

    def _date(self, match: re.Match[str], request: str) -> Answer:
        return self.calendar.now().strftime("%y.%m/%d")  # syndesi reads `%y.%m/%d`; p300.py read_date too

    def _time(self, match: re.Match[str], request: str) -> Answer:
        return self.calendar.now().strftime("%H:%M:%S")

    def _constant_temperature(self, match: re.Match[str], request: str) -> Answer:
        shown = self._panel.last_setpoint_c  # as TEMP? shows it; the constant one, as no program runs
        return f"{self._lab.thermal.setpoint_c if shown is None else shown:.1f},ON"

    def _constant_humidity(self, match: re.Match[str], request: str) -> Answer:
        if not self._humidity():
            return NO_PTCON
        humidity = self.settings.humidity
        return f"{humidity.setpoint_pct:.0f},{'ON' if humidity.on else 'OFF'}"

    def _temperature_only(self, match: re.Match[str], request: str) -> Answer:
        return NO_PTCON if not self._humidity() else UNKNOWN

    def _refrigeration_setting(self, match: re.Match[str], request: str) -> Answer:
        return f"REF{self.settings.refrigeration}"

    def _constant_refrigeration(self, match: re.Match[str], request: str) -> Answer:
        return self.settings.refrigeration_answer()

    def _compressor(self, match: re.Match[str], request: str) -> Answer:
        """One stage, running while the chamber conditions with refrigeration on (automatic: below the room's
        temperature); the first field the refrigeration setting (inferred: the libraries read the stages)."""
        thermal, setting = self._lab.thermal, self.settings.refrigeration
        running = thermal.powered and setting != 0 and (setting != AUTOMATIC_REFRIGERATION
                                                         or thermal.setpoint_c < thermal.ambient_c)
        return f"{setting},{'ON1' if running else 'OFF1'}"

    def _relays(self, match: re.Match[str], request: str) -> Answer:
        return counted(self.settings.relays_on)

    def _key_protection(self, match: re.Match[str], request: str) -> Answer:
        return "ON" if self.settings.key_protection else "OFF"

    def _mask(self, match: re.Match[str], request: str) -> Answer:
        return self.settings.srq_mask

    def _network(self, match: re.Match[str], request: str) -> Answer:
        return ",".join(self.settings.network)

    def _none_stored(self, match: re.Match[str], request: str) -> Answer:
        return counted([])  # no timer on or set, no program stored

    def _unsupported(self, match: re.Match[str], request: str) -> Answer:
        return UNSUPPORTED

    # ------------------------------------------------------------------ settings
    def _ok(self, request: str) -> str:
        return f"OK:{request}"

    def _power(self, match: re.Match[str], request: str) -> Answer:
        command = match[0]
        self._lab.thermal.set_power(self._lab.clock.now(), command in ("POWER,ON", "MODE,CONSTANT"))
        self._controller_on = command not in ("POWER,OFF", "MODE,OFF")
        return self._ok(request)

    def _temperature(self, match: re.Match[str], request: str) -> Answer:
        """`TEMP, S… H… L…`: the upper and lower limits within the chamber's own range (TYPE?'s maximum), then
        the set point, taken as the profile's own write takes it (clamped to the limits)."""
        if match["s"] == "OFF":
            return UNSUPPORTED  # temperature control switched off: not simulated
        if not any(match.group("s", "h", "l")):
            return PARAMETER
        if match["h"] or match["l"]:
            low, high = self._lab.controller_limits_c
            rated_low, rated_high = self._panel.rated_limits_c
            low = float(match["l"]) if match["l"] else low
            high = float(match["h"]) if match["h"] else high
            if not rated_low <= low < high <= rated_high:
                return OUT_OF_RANGE
            self._lab.controller_limits_c = (low, high)
        if match["s"]:
            self._panel.write_setpoint(self._lab.clock.now(), float(match["s"]))
        return self._ok(request)

    def _humidity_setting(self, match: re.Match[str], request: str) -> Answer:
        """`HUMI, S…|SOFF H… L…`: held (the constant humidity set point, on or off, and its limits); the air's
        humidity does not follow (no humidifier is simulated)."""
        if not self._humidity():
            return NO_PTCON
        if not any(match.group("s", "h", "l")):
            return PARAMETER
        humidity = self.settings.humidity
        low = float(match["l"]) if match["l"] else humidity.low_pct
        high = float(match["h"]) if match["h"] else humidity.high_pct
        setpoint = humidity.setpoint_pct if match["s"] in (None, "OFF") else float(match["s"])
        if not HUMIDITY_RANGE_PCT[0] <= low < high <= HUMIDITY_RANGE_PCT[1] \
                or match["s"] not in (None, "OFF") and not low <= setpoint <= high:
            return OUT_OF_RANGE
        humidity.low_pct, humidity.high_pct, humidity.setpoint_pct = low, high, setpoint
        if match["s"] is not None:
            humidity.on = match["s"] != "OFF"
        return self._ok(request)

    def _set_date(self, match: re.Match[str], request: str) -> Answer:
        try:
            day = date(2000 + int(match["year"]), int(match["month"]), int(match["day"]))
        except ValueError:
            return OUT_OF_RANGE
        self.calendar.set(datetime.combine(day, self.calendar.now().time()))
        return self._ok(request)  # the day of the week follows from the date

    def _set_time(self, match: re.Match[str], request: str) -> Answer:
        try:
            clock = time(int(match["hour"]), int(match["minute"]), int(match["second"]))
        except ValueError:
            return OUT_OF_RANGE
        self.calendar.set(datetime.combine(self.calendar.now().date(), clock))
        return self._ok(request)

    def _set_mask(self, match: re.Match[str], request: str) -> Answer:
        self.settings.srq_mask = match["mask"]
        return self._ok(request)

    def _reset_service_request(self, match: re.Match[str], request: str) -> Answer:
        return self._ok(request)  # no service request is ever raised here: nothing to reset

    def _set_key_protection(self, match: re.Match[str], request: str) -> Answer:
        if match["state"] == "ON" and not self._controller_on:
            return KEYS_WHILE_OFF
        self.settings.key_protection = match["state"] == "ON"
        return self._ok(request)

    def _set_refrigeration(self, match: re.Match[str], request: str) -> Answer:
        self.settings.refrigeration = int(match["step"])
        return self._ok(request)

    def _set_relays(self, match: re.Match[str], request: str) -> Answer:
        relays = {int(n) for n in match["relays"].split(",")}
        if not relays <= set(RELAYS):
            return OUT_OF_RANGE
        if match["state"] == "ON":
            self.settings.relays_on |= relays
        else:
            self.settings.relays_on -= relays
        return self._ok(request)

    def _set_network(self, match: re.Match[str], request: str) -> Answer:
        address, mask, gateway = match["address"], match["mask"], match["gateway"]
        try:
            for text in (address, mask, gateway):
                ipaddress.IPv4Address(text)
        except ValueError:
            return PARAMETER  # a field missing (`IPSET,,,`) or no address
        self.settings.network = (address, mask, gateway)
        return self._ok(request)


#: The requests served beyond the profile, as the controller reads them (a blank after a comma dropped, upper
#: case), in the order they are tried: (pattern, the method answering it or the refusal answered, whether it
#: is a setting, refused while the panel locks remote writes).
REQUESTS: tuple[tuple[re.Pattern[str], str, bool], ...] = tuple((re.compile(pattern), action, setting) for
                                                                pattern, action, setting in (
    # monitoring and the chamber's state
    (r"MON\?(,DETAIL)?", "_mon", False),
    (r"MODE\?(,DETAIL)?", "_mode_answer", False),
    (r"ROM\?(?P<display>,DISP)?", "_rom", False),
    (r"DATE\?", "_date", False),
    (r"TIME\?", "_time", False),
    (r"HUMI\?", "_temperature_only", False),
    (r"CONSTANT SET\?,TEMP", "_constant_temperature", False),
    (r"CONSTANT SET\?,HUMI", "_constant_humidity", False),
    (r"CONSTANT SET\?,REF", "_constant_refrigeration", False),
    (r"CONSTANT SET\?,RELAY|RELAY\?", "_relays", False),
    (r"SET\?", "_refrigeration_setting", False),
    (r"REF\?", "_compressor", False),
    (r"KEYPROTECT\?", "_key_protection", False),
    (r"MASK\?", "_mask", False),
    (r"IPSET\?", "_network", False),
    (r"TIMER (ON|USE)\?|PRGM USE\?,RAM", "_none_stored", False),
    # product temperature control (PTCON): the simulated chamber has none
    (r"(MON |TEMP |SET )?PTC\?|CONSTANT SET\?,PTC|SYSTEM SET\?,.*|PRGM DATA PTC\?,.*|TEMP PTC,.*|PTC,.*", NO_PTCON,
     False),
    # programs: none stored, none running
    (r"PRGM (MON|SET)\?|RUN PRGM( MON)?\?|PRGM,(PAUSE|CONTINUE|ADVANCE|END(,.*)?)", NOT_RUNNING, False),
    (rf"PRGM DATA\?,{_PROGRAM}(,.*)?|PRGM USE\?,{_PROGRAM}|PRGM ERASE,{_PROGRAM}|PRGM,RUN,{_PROGRAM}(,STEP\d+)?"
     r"|MODE,RUN\d+", NO_DATA, False),
    (r"MODE,RUN", PARAMETER, False),
    (r"PRGM DATA WRITE,PGM\d+,(EDIT|OVER WRITE) START", "_unsupported", False),
    (r"PRGM DATA WRITE,PGM\d+,EDIT (END|CANCEL)", EDIT_NOT_ALLOWED, False),
    (r"PRGM DATA WRITE,PGM\d+,.*", NOT_EDITING, False),
    # timers: none set (TIMER WRITE is not simulated)
    (r"TIMER LIST\?,[0-2]|TIMER ERASE,NO[0-2]|TIMER,(ON|OFF),[0-2]", NO_DATA, False),
    (r"TIMER WRITE,.*|RUN PRGM,.*|%\?|SRQ\?", "_unsupported", False),
    # settings
    (r"POWER,(ON|OFF)|MODE,(OFF|CONSTANT|STANDBY)", "_power", True),
    (rf"TEMP,{_LIMITS}", "_temperature", True),
    (rf"HUMI,{_LIMITS}", "_humidity_setting", True),
    (r"DATE,(?P<year>\d{1,2})\.(?P<month>\d{1,2})/(?P<day>\d{1,2})(\. ?[A-Z]{3})?", "_set_date", True),
    (r"TIME,(?P<hour>\d{1,2}):(?P<minute>\d{1,2}):(?P<second>\d{1,2})", "_set_time", True),
    (r"MASK,(?P<mask>0[01]{3}00[01]0)", "_set_mask", True),
    (r"SRQ,RESET", "_reset_service_request", True),
    (r"KEYPROTECT,(?P<state>ON|OFF)", "_set_key_protection", True),
    (r"SET,REF(?P<step>\d)", "_set_refrigeration", True),
    (r"RELAY,(?P<state>ON|OFF),(?P<relays>\d+(,\d+)*)", "_set_relays", True),
    (r"IPSET,(?P<address>[^,]*),(?P<mask>[^,]*),(?P<gateway>[^,]*)", "_set_network", True),
    # a known command with a parameter it cannot read (a set point that is no number, `TEMP, Snan`, stays
    # unknown, as the profile's own write meets it)
    (r"(HUMI|DATE|TIME|MASK|KEYPROTECT|SET|RELAY|IPSET|SRQ|POWER|MODE),.*", PARAMETER, True),
))
