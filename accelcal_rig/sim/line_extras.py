"""What a simulated line controller answers beyond its profile's operations, by the profile's dialect: the
requests the makers' libraries and other public clients send that the rig's driver does not (ESPEC's `MON?`,
`MODE?`, `POWER,ON`; SIMSERV's status with a selector, other digital outputs, a wrong field count), and the
values the profile's own answers take from the chamber's state (ESPEC's sensor types, SIMSERV's status).
SCPI and plain profiles have none: the F4T documents no error reply, so a header it does not know is met
with silence, as is any request the Thermotron profile does not have."""

from __future__ import annotations

from typing import Protocol

from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol, Operation
from accelcal_rig.protocols.simserv_commands import FIELDS, SEPARATOR, command_fields
from accelcal_rig.sim.lab import VirtualLab


class Panel(Protocol):
    """The simulated controller's own state beyond the lab's (tests set it)."""

    local_mode: bool
    alarms: int
    warnings: int
    identity: str


class Unknown:
    """A request the controller family does not know: answered with the profile's unknown-command answer."""


UNKNOWN = Unknown()


class Extras:
    """plain and scpi: nothing beyond the profile. Methods are called with the lab's lock held."""

    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        self._protocol, self._lab, self._panel = protocol, lab, panel

    def values(self) -> dict[str, object]:
        """Fields the profile's answers take from the state, beyond the generic ones."""
        return {}

    def carried_out(self, operation: Operation) -> None:
        """A profile operation was carried out (a write)."""

    def answer(self, request: str) -> str | None | Unknown:
        return UNKNOWN


class EspecExtras(Extras):
    """ESPEC P300/SCP-220 (ChamberConnectLibrary `p300.py`, ATWG, espec_pr3j): the controller is OFF, in
    STANDBY (on, not conditioning) or CONSTANT (conditioning); a temperature-only chamber (a profile without
    `humidity`) answers `TYPE?` with three fields, `MON?` with an empty humidity field and `HUMI?` with
    `NA:CONT NOT READY-1` (ESPEC's library: "Chamber does not support PTCON/Humidity")."""

    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        super().__init__(protocol, lab, panel)
        self._controller_on = True

    def _humidity(self) -> bool:
        return self._protocol.humidity is not None

    def _mode(self) -> str:
        if self._lab.thermal.powered:
            return "CONSTANT"
        return "STANDBY" if self._controller_on else "OFF"

    def values(self) -> dict[str, object]:
        return {"sensors": "T,T" if self._humidity() else "T", "alarm": str(self._panel.alarms)}

    def carried_out(self, operation: Operation) -> None:
        if operation in ("power_on", "power_off"):
            self._controller_on = True  # CONSTANT and STANDBY both leave the controller on

    def answer(self, request: str) -> str | None | Unknown:
        command = request.replace(", ", ",").upper()
        if command in ("MON?", "MON?,DETAIL"):
            humidity = f"{self._lab.chamber_humidity_pct():.0f}" if self._humidity() else ""
            return f"{self._lab.chamber_reading_c():.1f},{humidity},{self._mode()},{self._panel.alarms}"
        if command in ("MODE?", "MODE?,DETAIL"):
            return self._mode()  # no program runs here, so DETAIL has nothing to add
        if command == "HUMI?" and not self._humidity():
            return "NA:CONT NOT READY-1"
        if command.split(",")[:2] in (["PRGM", "PAUSE"], ["PRGM", "CONTINUE"], ["PRGM", "ADVANCE"], ["PRGM", "END"]):
            return "NA:CONT NOT READY-2"  # the chamber is not running a program (none runs here)
        if command in ("POWER,ON", "POWER,OFF", "MODE,OFF", "MODE,CONSTANT", "MODE,STANDBY"):
            if self._panel.local_mode and self._protocol.local_mode_answer is not None:
                return self._protocol.local_mode_answer
            self._lab.thermal.set_power(self._lab.clock.now(), command in ("POWER,ON", "MODE,CONSTANT"))
            self._controller_on = command not in ("POWER,OFF", "MODE,OFF")
            return f"OK:{request}"
        return UNKNOWN


class SimservExtras(Extras):
    """Vötsch/Weiss SIMSERV (IzaakWN, SengerM, basil): status 10012 is 1 (idle) + 2 (manual run on) + 4
    (warnings) + 8 (alarms); 14001 sets digital output n (1 is the manual run, the profile's power command;
    the purge output is the profile's, chamber wiring), 14003 reads one back; a known command number with a
    field count it does not take is `-6`; one the simulated chamber has no data for (another control
    variable, the year of manufacture, output names) is `-8`, data could not be read."""

    def __init__(self, protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> None:
        super().__init__(protocol, lab, panel)
        self._outputs: dict[str, str] = {}
        purge = protocol.purge_on
        number, fields = command_fields(purge.send) if purge is not None else ("", [])
        self._purge_output = fields[1] if number == "14001" and len(fields) == 3 else None

    def _status(self) -> int:
        return (1 + 2 * self._lab.thermal.powered + 4 * (self._panel.warnings > 0)
                + 8 * (self._panel.alarms > 0))

    def values(self) -> dict[str, object]:
        return {"alarm": str(self._status())}

    def answer(self, request: str) -> str | None | Unknown:
        number, fields = command_fields(request)
        if number not in FIELDS:
            return UNKNOWN
        if len(fields) not in FIELDS[number]:
            return "-6"
        if number == "10012":
            return f"1{SEPARATOR}{self._status()}"
        if number == "99997" and fields[1] == "1":
            return f"1{SEPARATOR}{self._panel.identity}"
        if number == "14001":
            return self._set_output(fields[1], fields[2])
        if number == "14003":
            return f"1{SEPARATOR}{self._output(fields[1])}"
        return "-8"

    def _set_output(self, output: str, value: str) -> str:
        if value not in ("0", "1"):
            return "-6"
        now = self._lab.clock.now()
        if output == "1":
            self._lab.thermal.set_power(now, value == "1")
        elif output == self._purge_output:
            self._lab.moisture.set_purge(now, value == "1")
        else:
            self._outputs[output] = value  # wired to nothing simulated
        return "1"

    def _output(self, output: str) -> str:
        if output == "1":
            return "1" if self._lab.thermal.powered else "0"
        if output == self._purge_output:
            return "1" if self._lab.moisture.purge_on else "0"
        return self._outputs.get(output, "0")


def extras_for(protocol: ChamberLineProtocol, lab: VirtualLab, panel: Panel) -> Extras:
    """The extras of the profile's dialect."""
    kinds: dict[str, type[Extras]] = {"espec": EspecExtras, "simserv": SimservExtras}
    return kinds.get(protocol.dialect, Extras)(protocol, lab, panel)
