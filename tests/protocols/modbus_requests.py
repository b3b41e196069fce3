"""The registers the makers' Modbus clients use that the simulated controllers do not hold, as data: each range
with the client and function that uses it and why it is not simulated. The simulator answers them as the
controller does an address it has not (Modbus exception 2); tests/protocols/client_sweep.py counts a request
here as NOT SIMULATED rather than as a deviation. Every other register ESPEC's ChamberConnectLibrary reads or
writes is served (protocols/chamber_registers.py, the driver's map; sim/register_panels.py, the rest)."""

from __future__ import annotations

from dataclasses import dataclass

CCL = "EspecNorthAmerica/ChamberConnectLibrary"


@dataclass(frozen=True)
class NotSimulated:
    profile: str
    first: int  # zero-based register address
    last: int
    client: str
    where: str
    why: str


NOT_SIMULATED: tuple[NotSimulated, ...] = (
    NotSimulated("watlow-f4", 3500, 3899, CCL, "watlowf4.py get_prgm_name, set_prgm_name", "no stored profiles"),
    NotSimulated("watlow-f4", 4000, 4199, CCL, "watlowf4.py prgm_*, get_prgm*, set_prgm, get_program*",
                 "no profile engine: the simulated chamber runs the rig's set points, never a stored profile"),
    NotSimulated("watlow-f4", 103, 115, CCL, "watlowf4.py get_loop_power",
                 "no output power: the simulated chamber has no heater or cooler outputs"),
    NotSimulated("watlow-f4t", 16564, 16630, CCL, "watlowf4t.py prgm_*, get_prgm*",
                 "no profile engine: the simulated chamber runs the rig's set points, never a stored profile"),
    NotSimulated("watlow-f4t", 18888, 18888, CCL, "watlowf4t.py prgm_start, get_prgm_steps, set_program",
                 "no profile engine"),
    NotSimulated("watlow-f4t", 2784, 2785, CCL, "watlowf4t.py get_loop_power, set_loop_power",
                 "no manual output power"),
    NotSimulated("watlow-f4t", 2808, 2809, CCL, "watlowf4t.py get_loop_power", "no output power"),
    NotSimulated("watlow-f4t", 6844, 6910, CCL, "watlowf4t.py get_event, set_event (keys 9-12), stop, set_operation",
                 "no front-panel keys: the chamber runs on event 1 (Power), which is served"),
    NotSimulated("watlow-f4t", 16, 30, CCL, "watlowf4t.py process_controller",
                 "no part number: the simulated F4T's model code is not stated by any source we have"),
    NotSimulated("watlow-f4t", 37548, 37567, CCL, "watlowf4t.py set_network_settings", "no network settings"),
)


def not_simulated(profile: str, address: int) -> NotSimulated | None:
    """The entry whose range holds `address` on `profile`, if any."""
    return next((entry for entry in NOT_SIMULATED if entry.profile == profile and entry.first <= address <= entry.last),
                None)
