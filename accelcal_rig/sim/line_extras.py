"""What a simulated line controller answers beyond its profile's operations, by the profile's dialect: the
requests the makers' libraries and other public clients send that the rig's driver does not, and the values
the profile's own answers take from the chamber's state. ESPEC's are in sim/espec_extras.py, the F4T's SCPI
in sim/f4t_scpi_extras.py, SIMSERV's here (its status with a selector, other digital outputs, a wrong field
count). The plain (Thermotron) profile has none: a request it does not have is met with silence."""

from __future__ import annotations

from accelcal_rig.protocols.chamber_lines import ChamberLineProtocol
from accelcal_rig.protocols.simserv_commands import FIELDS, SEPARATOR, command_fields
from accelcal_rig.sim.controller_extras import UNKNOWN, Answer, Extras, Panel
from accelcal_rig.sim.espec_extras import EspecExtras
from accelcal_rig.sim.f4t_scpi_extras import F4tScpiExtras
from accelcal_rig.sim.lab import VirtualLab


class SimservExtras(Extras):
    """Vötsch/Weiss SIMSERV (IzaakWN, SengerM, basil): status 10012 is 1 (idle) + 2 (manual run on) + 4
    (warnings) + 8 (alarms); 14001 sets digital output n (1 is the manual run, the profile's power command;
    the purge output is the profile's, chamber wiring), 14003 reads one back; a known command number with a
    field count it does not take is `-6`; one the simulated chamber has no data for (another control
    variable, the year of manufacture, output names, messages, programs) is `-8`, data could not be read."""

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

    def answer(self, request: str) -> Answer:
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
    """The extras of the profile's dialect (SCPI's are the F4T's, the one SCPI chamber profile)."""
    kinds: dict[str, type[Extras]] = {"espec": EspecExtras, "simserv": SimservExtras, "scpi": F4tScpiExtras}
    return kinds.get(protocol.dialect, Extras)(protocol, lab, panel)
