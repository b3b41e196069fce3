"""What the handlers of a running campaign's steps share, typed: the rig, the run's services, and the state one
step leaves for another (the temperatures a soak settled at, the software ramp, the table's last angles, a
cool-down's schedule, the purge). Handlers read and write it here, never each other's fields."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from accelcal_rig.config.procedure import Procedure, RampMethod
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.geometry import fixture_to_dut
from accelcal_rig.engine.audience import Reporter
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.engine.states import StateMachine
from accelcal_rig.errors import InstrumentError
from accelcal_rig.fit.early_check import dropped
from accelcal_rig.instruments.capabilities import alarm_active
from accelcal_rig.instruments.interfaces import Chamber, RigInstruments, Sensor, TruthSource, Turntable
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.plan.compile import Plan
from accelcal_rig.plan.kinematics import TurntableKinematics
from accelcal_rig.store.writer import CampaignWriter


@dataclass
class SoftwareRamp:
    """The ramp method's chamber setpoint, moved by the program at the procedure's rate: from `from_c` at
    clock time `started_s` toward `toward_c`, where it stops."""

    settings: RampMethod
    started_s: float
    from_c: float
    toward_c: float
    written_s: float = float("-inf")

    def setpoint_c(self, t_s: float) -> float:
        travelled = self.settings.rate_c_per_min / 60.0 * (t_s - self.started_s)
        return float(min(self.from_c + travelled, self.toward_c) if self.toward_c > self.from_c
                     else max(self.from_c - travelled, self.toward_c))

    def arrival_s(self, until_c: float) -> float:
        """The clock time the ramp reaches `until_c`."""
        return self.started_s + abs(until_c - self.from_c) / (self.settings.rate_c_per_min / 60.0)


@dataclass
class DutThermalState:
    """What the chamber's steps leave for the poses."""

    #: Each DUT's temperature when its last soak settled: the band its poses are judged against.
    settled_c: np.ndarray
    #: True while the DUT temperatures move on purpose (cool-down, ramp): no band warnings then.
    moving: bool = False
    #: When the chamber air (or the software ramp) last reached its setpoint: where a soak's deadline starts.
    reached_s: float = 0.0
    #: The last ramp's air polls (clock s, °C), from the set point's write: the soak after it keeps them.
    ramp_t_s: list[float] = field(default_factory=list)
    ramp_chamber_c: list[float] = field(default_factory=list)
    #: The ramp method's software ramp once running.
    software_ramp: SoftwareRamp | None = None


@dataclass
class TableState:
    """The table's angles as last read, and the setpoint they were read at: the first move at each setpoint
    reads them afresh (hours of soak: the table may have been moved, or have drifted)."""

    angles_deg: np.ndarray | None = None
    setpoint_c: float | None = None
    #: The rate the rate axis turns at (°/s, signed) and the pose it turns in, None at rest.
    rate_dps: float = 0.0
    turning_in: tuple[float, ...] | None = None


@dataclass
class CooldownState:
    """When this run let the chamber go (None: not yet), and the records taken since."""

    released_s: float | None = None
    since_release: int = 0


@dataclass
class RunContext:
    """One run of a campaign, as its step handlers see it."""

    procedure: Procedure
    rig: RigConfig
    plan: Plan
    instruments: RigInstruments
    retrier: Retrier
    clock: Clock
    events: EventLog
    writer: CampaignWriter
    machine: StateMachine
    report: Reporter
    dut: DutThermalState = field(init=False)
    table: TableState = field(default_factory=TableState)
    cooldown: CooldownState = field(default_factory=CooldownState)
    #: Whether this run last switched the dry-air purge on (None: it has not switched it).
    purge_on: bool | None = None
    #: The DUTs the early check dropped (`early_check.action: drop`), by serial: measured on, not checked again,
    #: left out of the fit. A resumed run reads them from the campaign's events.
    dropped: set[str] = field(init=False)
    #: The ranges the DUTs are configured at now (engine/step_ranges.py): `acquisition.ranges` from the preflight on.
    sensor_ranges: dict[str, float] = field(default_factory=dict)
    #: Fixture frame → each DUT's frame, by serial.
    fixture_to_dut: dict[str, np.ndarray] = field(init=False)
    kinematics: TurntableKinematics = field(init=False)

    def __post_init__(self) -> None:
        self.dut = DutThermalState(np.zeros(len(self.sensors)))
        self.dropped = set(dropped(self.writer.campaign.events))
        self.fixture_to_dut = {s.serial: fixture_to_dut(s.mount_euler_deg) for s in self.rig.fixture.sensors}
        self.kinematics = TurntableKinematics(self.rig.turntable.axes)

    @property
    def chamber(self) -> Chamber:
        return self.instruments.chamber

    @property
    def turntable(self) -> Turntable:
        return self.instruments.turntable

    @property
    def sensors(self) -> list[Sensor]:
        return self.instruments.sensors

    @property
    def block_s(self) -> float:
        """How long a pose's samples take: at the slowest DUT's rate."""
        acquisition = self.procedure.acquisition
        return acquisition.block_s([odr_hz_of(s.part, acquisition.odr_hz) for s in self.sensors])

    @property
    def truth(self) -> TruthSource | None:
        return self.instruments.truth

    def read_chamber_c(self) -> float:
        """Chamber air temperature; an active controller alarm is a fault, never a reading to wait out."""
        if alarm_active(self.chamber):
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): controller alarm active")
        self.report.chamber_c = self.chamber.read_temperature_c()
        return self.report.chamber_c

    def write_ramp_setpoint(self, arrived: bool = False) -> None:
        """Write the software ramp's current setpoint, at most every `ramp.update_s` (`arrived`: now, where
        a segment ends: the chamber must be left at the ramp's end, not an update short of it); nothing
        unless a software ramp runs."""
        ramp = self.dut.software_ramp
        if ramp is None:
            return
        now = self.clock.now()
        if arrived or now - ramp.written_s >= ramp.settings.update_s:
            self.chamber.write_setpoint_c(round(ramp.setpoint_c(now), 3))
            ramp.written_s = now
