"""What a simulated Modbus controller holds beyond the register map the driver uses: the registers the makers'
own library reads and writes (ESPEC's ChamberConnectLibrary, `watlowf4.py` and `watlowf4t.py`), answered from
the simulated chamber's state as the controller keeps them. The driver's map (protocols/chamber_registers.py)
stays what the driver needs; a panel is the rest of the controller, so a client written for the real one finds
what it reads there. Registers neither holds answer Modbus exception 2, as the controller does for an address
it has not (profiles, cascade loops, network settings: docs/instruments.md lists them NOT SIMULATED).

Each register's meaning and source: docs/instruments.md, "Watlow F4 and F4T: the rest of the controller"."""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from dataclasses import dataclass, field

from accelcal_rig.protocols.chamber_registers import ChamberRegisterMap, encode_temperature
from accelcal_rig.sim.lab import VirtualLab

Words = list[int]


@dataclass
class PanelState:
    """The controller's own settings a client may change: its clock (kept as an offset from the simulation's),
    event outputs beyond the chamber's power, and the loop's control mode."""

    clock_start: dt.datetime
    clock_offset_s: float = 0.0
    events: dict[int, int] = field(default_factory=dict)
    control_mode: int = 10

    def now(self, lab: VirtualLab) -> dt.datetime:
        return self.clock_start + dt.timedelta(seconds=lab.clock.now() + self.clock_offset_s)


@dataclass(frozen=True)
class PanelRegister:
    """A run of registers: how it reads from the state, and how a write changes it (None: read-only, exception
    2 on a write as for an address the controller does not accept writes at; a write returning False: exception
    3, a value the controller refuses)."""

    address: int
    count: int
    read: Callable[[PanelState, VirtualLab], Words]
    write: Callable[[PanelState, VirtualLab, Words], bool] | None = None


def _fixed(*words: int) -> Callable[[PanelState, VirtualLab], Words]:
    return lambda state, lab: list(words)


def _accept(allowed: tuple[int, ...]) -> Callable[[PanelState, VirtualLab, Words], bool]:
    """A command register (terminate, pause, resume): carried out at once; with no profile running, a no-op."""
    return lambda state, lab, words: all(word in allowed for word in words)


def _event(register: int, on: int, off: int) -> PanelRegister:
    """An event output the simulated chamber has no wiring behind (the power event is the map's): kept."""

    def write(state: PanelState, lab: VirtualLab, words: Words) -> bool:
        if words[0] not in (on, off):
            return False
        state.events[register] = words[0]
        return True

    return PanelRegister(register, 1, lambda state, lab: [state.events.get(register, off)], write)


# --- Watlow F4 (watlowf4.py) -------------------------------------------------------------------------------

def _f4_clock(state: PanelState, lab: VirtualLab) -> Words:
    now = state.now(lab)
    return [now.hour, now.minute, now.second, now.month, now.day, now.year]


def _f4_set_clock(state: PanelState, lab: VirtualLab, words: Words) -> bool:
    return _set_clock(state, lab, hour=words[0], minute=words[1], second=words[2], month=words[3], day=words[4],
                      year=words[5])


def _set_clock(state: PanelState, lab: VirtualLab, **parts: int) -> bool:
    current = state.now(lab)
    fields = {name: parts.get(name, getattr(current, name))
              for name in ("year", "month", "day", "hour", "minute", "second")}
    try:
        wanted = dt.datetime(**fields)
    except ValueError:  # a 30 February, an hour 25: refused, the clock kept
        return False
    state.clock_offset_s += (wanted - current).total_seconds()
    return True


#: No profile runs in the simulated controllers: the profile status says constant, the engine takes its
#: commands (terminate, pause, resume) as the real one does with nothing to act on, and all 40 slots are free.
WATLOW_F4_PANEL = (
    PanelRegister(200, 1, _fixed(0)),                       # profile status: 0 constant (2 running, 3 paused)
    PanelRegister(608, 1, _fixed(0)),                       # input 1's sensor type: 0 temperature
    PanelRegister(1209, 1, _fixed(0), _accept((0, 1))),     # resume profile
    PanelRegister(1210, 1, _fixed(0), _accept((0, 1))),     # hold (pause) profile
    PanelRegister(1217, 1, _fixed(0), _accept((0, 1))),     # terminate profile
    PanelRegister(1218, 1, _fixed(40)),                     # profile slots free
    PanelRegister(1916, 6, _f4_clock, _f4_set_clock),       # real-time clock: h, min, s, month, day, year
    *(_event(2000 + 10 * (n - 1), 1, 0) for n in range(2, 9)),   # events 2…8 (event 1 is the map's power)
)


# --- Watlow F4T (watlowf4t.py) ------------------------------------------------------------------------------

def _f4t_clock(state: PanelState, lab: VirtualLab) -> Words:
    now = state.now(lab)
    words = [0] * 12
    words[0::2] = [now.hour, now.minute, now.second, now.month, now.day, now.year]
    return words


def _f4t_clock_word(index: int) -> Callable[[PanelState, VirtualLab], Words]:
    return lambda state, lab: [_f4t_clock(state, lab)[2 * index]]


def _f4t_clock_part(name: str) -> Callable[[PanelState, VirtualLab, Words], bool]:
    return lambda state, lab, words: _set_clock(state, lab, **{name: words[0]})


def _f4t_mode_write(state: PanelState, lab: VirtualLab, words: Words) -> bool:
    if words[0] not in (10, 54, 62):                          # auto, manual, off
        return False
    state.control_mode = words[0]
    return True


def _f4t_run_signal(lab: VirtualLab) -> Words:
    return [63 if lab.thermal.powered else 62]               # on / off


def _f4t_working_setpoint(encode: Callable[[float], Words]) -> Callable[[PanelState, VirtualLab], Words]:
    return lambda state, lab: encode(lab.thermal.setpoint_c)


def watlow_f4t_panel(encode: Callable[[float], Words]) -> tuple[PanelRegister, ...]:
    """The F4T's (floats encoded as the map says)."""
    return (
        PanelRegister(2730, 1, lambda state, lab: [state.control_mode], _f4t_mode_write),  # user control mode
        PanelRegister(2810, 2, _f4t_working_setpoint(encode)),  # working set point (no ramp: the set point)
        PanelRegister(2814, 1, lambda state, lab: [state.control_mode]),  # loop control mode in effect
        PanelRegister(16568, 1, _fixed(148)),                 # profile state: terminate (149 running, 146 pause)
        *(PanelRegister(1356 + 100 * i, 1, _fixed(88)) for i in range(1, 6)),  # alarms 2…6: startup (inactive)
        *(PanelRegister(14664 + 2 * i, 1, _f4t_clock_word(i), _f4t_clock_part(part))  # clock, every other register
          for i, part in enumerate(("hour", "minute", "second", "month", "day", "year"))),
        *(PanelRegister(14665 + 2 * i, 1, _fixed(0)) for i in range(6)),
        PanelRegister(33718, 1, lambda state, lab: _f4t_run_signal(lab)),  # module 1 I/O point 1: the run signal
        # The chamber's over-temperature limit, a limit module in slot 5 (the library's default `limits=[5]`):
        # its state clear (129), no error (61 none), its sensor ok (138) — never tripped in a simulation.
        PanelRegister(11490, 1, _fixed(129)),
        PanelRegister(11504, 1, _fixed(138)),
        PanelRegister(11528, 1, _fixed(61)),
        *(_event(register, 63, 62) for register in (16596, 16598, 16600, 16822, 16824, 16826, 16828)),
    )


def panel_for(profile: str, registers: ChamberRegisterMap) -> tuple[PanelRegister, ...]:
    """The panel of a built-in profile's controller (none for a profile without one)."""
    if profile == "watlow-f4":
        return WATLOW_F4_PANEL
    if profile == "watlow-f4t":
        return watlow_f4t_panel(lambda temperature_c: encode_temperature(registers, temperature_c))
    return ()
