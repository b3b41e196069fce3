"""Pose schedules as a procedure states them: the paper's 24 positions, six positions, a sphere, tilts, or
explicit turntable angles."""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, field_validator, model_validator

from accelcal_rig.config.bounds import AngleDeg, Real, StrictModel, Whole

#: Most orientations a schedule may list (each is solved for the turntable's angles when the plan compiles).
MAX_SCHEDULE_POSES = 2_000
#: Most orientations `order: shortest-travel` orders (it solves every remaining pose from each one visited).
MAX_ORDERED_POSES = 100


class GeneratedSchedule(StrictModel):
    """A schedule of gravity directions the plan solves for turntable angles. `order`: visit them as the
    schedule lists them, or in the order that turns the table least (nearest next pose by travel time, from
    where the table stands; each pose keeps its number): a sphere's poses as listed step ~140° about the
    inner axis each, and at a soaked setpoint the table's travel is rig time."""

    order: Literal["as-listed", "shortest-travel"] = "as-listed"

    @property
    def size(self) -> int:
        raise NotImplementedError

    @model_validator(mode="after")
    def _few_enough_to_order(self) -> GeneratedSchedule:
        if self.order == "shortest-travel" and self.size > MAX_ORDERED_POSES:
            raise ValueError(f"order: shortest-travel orders at most {MAX_ORDERED_POSES} poses, this schedule has "
                             f"{self.size}")
        return self


class Paper24Schedule(GeneratedSchedule):
    """Table 1 of the paper: eight 45° steps about each of the sensor's z, y and x axes."""

    kind: Literal["paper-24"]
    size: ClassVar[int] = 24


class SixPositionSchedule(GeneratedSchedule):
    """The classic six positions: each sensor axis up, then down."""

    kind: Literal["six-position"]
    size: ClassVar[int] = 6


class SphereSchedule(GeneratedSchedule):
    """`count` gravity directions spread evenly over the sphere (Fibonacci lattice)."""

    kind: Literal["sphere"]
    count: Whole = Field(ge=6, le=MAX_SCHEDULE_POSES)

    @property
    def size(self) -> int:
        return self.count


class TiltSchedule(GeneratedSchedule):
    """Poses given as pitch and roll of the fixture (paper Eq. 10, Table 5), in degrees: pitch tilts the
    y axis up, roll tilts the x axis down; (0, 0) is level with z up."""

    kind: Literal["tilt"]
    pitch_roll_deg: list[tuple[Real, Real]] = Field(min_length=1, max_length=MAX_SCHEDULE_POSES)

    @property
    def size(self) -> int:
        return len(self.pitch_roll_deg)

    @field_validator("pitch_roll_deg")
    @classmethod
    def _within_quarter_turn(cls, value: list[tuple[float, float]]) -> list[tuple[float, float]]:
        if any(not -90.0 <= p <= 90.0 or not -180.0 <= r <= 180.0 for p, r in value):
            raise ValueError("pitch must lie within ±90° and roll within ±180°")
        return value


class ExplicitSchedule(StrictModel):
    """Turntable axis angles given pose by pose, in degrees, in the rig's axis order."""

    kind: Literal["explicit"]
    angles_deg: list[Annotated[list[AngleDeg], Field(min_length=1, max_length=6)]] = Field(
        min_length=1, max_length=MAX_SCHEDULE_POSES)

    @property
    def size(self) -> int:
        return len(self.angles_deg)


Schedule = Annotated[
    Paper24Schedule | SixPositionSchedule | SphereSchedule | TiltSchedule | ExplicitSchedule,
    Field(discriminator="kind")
]
