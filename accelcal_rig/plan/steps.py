"""The steps a plan is made of: what the rig does, in the order it does it.

Each step is plain data. The engine has one handler per step type and runs a plan by dispatching on it, so
a new kind of step is a new type here and a handler there; the runner itself does not change.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar


@dataclass(frozen=True)
class Pose:
    """One turntable position: `number` is 1-based like the paper's Table 1."""

    number: int
    angles_deg: tuple[float, ...]
    gravity_fixture: tuple[float, float, float]


@dataclass(frozen=True)
class Ramp:
    """Set the chamber to the setpoint and wait for its air to reach it."""

    setpoint_c: float


@dataclass(frozen=True)
class Soak:
    """Wait until every DUT's temperature is stable at the setpoint; stores the soak trace under `key`."""

    key: str
    setpoint_c: float
    stored_kind: ClassVar[str] = "soak"


@dataclass(frozen=True)
class SetPurge:
    """Switch the chamber's dry-air purge on or off before going to the setpoint (`frost.purge_below_c`)."""

    setpoint_c: float
    on: bool


@dataclass(frozen=True)
class AwaitDewPointMargin:
    """After a warming step: wait until every DUT is `frost.dew_point_margin_c` above the air's dew point."""

    setpoint_c: float


@dataclass(frozen=True)
class StartSoftwareRamp:
    """The ramp method: from here on the chamber setpoint moves at the procedure's rate from `setpoint_c`
    to `toward_c` (the last setpoint; a bidirectional ramp's way back, the last band of its return)."""

    setpoint_c: float
    toward_c: float


@dataclass(frozen=True)
class RampSegment:
    """Keep the software ramp moving until it has reached `until_c`."""

    setpoint_c: float
    until_c: float


@dataclass(frozen=True)
class AdvanceRamp:
    """Write the software ramp's current setpoint (at most every `ramp.update_s`): between poses taken on it."""

    setpoint_c: float


@dataclass(frozen=True)
class CheckSetpoint:
    """After a setpoint's calibration poses: every DUT against its own fit of them (the early check), while
    the campaign can still act on what it finds. Stores no record: a plan's fingerprint is the same with it
    or without it."""

    setpoint_c: float


@dataclass(frozen=True)
class Measurement:
    """A block of samples from every DUT at `pose`, stored under `key`."""

    key: str
    setpoint_c: float
    pose: Pose
    stored_kind: ClassVar[str] = "pose"

    @property
    def rate_fixture_dps(self) -> tuple[float, float, float]:
        """The table's angular rate in the fixture frame while the samples are taken: at rest."""
        return (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class MeasurePose(Measurement):
    """Move to the pose, settle, acquire, store."""


@dataclass(frozen=True)
class VerifyPose(Measurement):
    """A verification pose: measured like a calibration pose, stored apart, never seen by the fit."""

    stored_kind: ClassVar[str] = "verify"


@dataclass(frozen=True)
class CooldownRecord(Measurement):
    """A cool-down's `number`-th record at the pose it holds: the first at the setpoint, after which the chamber
    is let go, then one every `cooldown.record_every_s`."""

    number: int


FIXTURE_AXES = "xyz"


@dataclass(frozen=True)
class RateStep(Measurement):
    """Turn the table's `rate_axis` so the fixture turns at `rate_dps` (signed, right-handed about its `about`
    axis, which the pose has brought to the rate axis or the rate axis lies along; `table_sign` −1 where the
    table axis points against it), hold it, acquire, store. The table keeps turning after it: the next rate
    step about the same axis starts from this rate, a StopRotation ends the run of them."""

    about: str
    rate_dps: float
    rate_axis: int
    table_sign: float = 1.0
    stored_kind: ClassVar[str] = "rate"

    @property
    def table_rate_dps(self) -> float:
        """The rate the table axis is commanded and reads back, about its own direction."""
        return self.table_sign * self.rate_dps

    @property
    def rate_fixture_dps(self) -> tuple[float, float, float]:
        rate = [0.0, 0.0, 0.0]
        rate[FIXTURE_AXES.index(self.about)] = self.rate_dps
        return (rate[0], rate[1], rate[2])


@dataclass(frozen=True)
class VerifyRate(RateStep):
    """A verification rate step: turned like a calibration rate, stored apart, never seen by the fit."""

    stored_kind: ClassVar[str] = "verify-rate"


@dataclass(frozen=True)
class StopRotation:
    """Bring the turning rate axis to rest (at the acceleration of the last rate step) and wait until it is."""

    setpoint_c: float
    rate_axis: int
    acceleration_dps2: float
    from_rate_dps: float


@dataclass(frozen=True)
class NoiseBlock(Measurement):
    """The `number`-th block of a still noise record at the pose it holds: the blocks follow one another with
    nothing moving between them."""

    number: int
    stored_kind: ClassVar[str] = "noise"


Step = (Ramp | Soak | SetPurge | AwaitDewPointMargin | StartSoftwareRamp | RampSegment | AdvanceRamp | MeasurePose
        | VerifyPose | CooldownRecord | RateStep | VerifyRate | StopRotation | NoiseBlock | CheckSetpoint)
#: The steps that store a record in the campaign (what its stored plan lists).
Record = Soak | Measurement


@dataclass(frozen=True)
class Stage:
    """One setpoint's steps: `entry` brings the rig there, `body` measures.

    `restart_entry` replaces `entry` when a run begins at this setpoint (a resumed run, or the one after a
    skipped soak): the ramp method's later setpoints ride on a software ramp that such a run has not started.
    """

    setpoint_c: float
    entry: tuple[Step, ...]
    body: tuple[Step, ...]
    restart_entry: tuple[Step, ...]

    @cached_property
    def records(self) -> tuple[Record, ...]:
        """Every record this setpoint may store: its soak (whichever entry soaks), then its measurements."""
        soaks = [s for s in (*self.entry, *self.restart_entry) if isinstance(s, Soak)]
        return (*soaks[:1], *(s for s in self.body if isinstance(s, Measurement)))
