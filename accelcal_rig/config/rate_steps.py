"""A gyroscope's part of a procedure: the rate steps a rate table turns at every setpoint, and the still
noise record the Allan deviation is read from."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from accelcal_rig.config.bounds import Real, StrictModel, Whole

FixtureAxis = Literal["x", "y", "z"]
#: A rate step's rate: at least 0.1 °/s, ten times the floor below which a rate read back is taken as rest
#: (engine/rate_steps.py's RATE_FLOOR_DPS, 0.01 °/s): a slower one could not be told from a table at rest.
RateDps = Annotated[Real, Field(ge=0.1, le=10_000)]


class RateSteps(StrictModel):
    """Constant rates about each fixture axis in turn, each in both directions: the fixture axis is brought to
    a table axis with a rate mode that can turn the fixture about it (plan/gyro_steps.py says which), then the
    table turns at each rate, holds it for `settle_s` and the samples are taken."""

    rates_dps: list[RateDps] = Field(min_length=1, max_length=32, description="magnitudes, each turned both ways "
                                     "about each axis of `about`; at most the part's range and the table's limit")
    about: list[FixtureAxis] = Field(["x", "y", "z"], min_length=1, max_length=3,
                                     description="the fixture axes turned in turn, each brought to a rate axis")
    axis: str | None = Field(None, max_length=32, description="the one table axis that turns every fixture axis "
                                                              "(default: each by the outermost rate axis that can)")
    acceleration_dps2: Real | None = Field(None, gt=0, le=100_000, description="how fast each rate is reached "
                                           "(default: the axis's max_acceleration_dps2)")
    settle_s: Real = Field(1.0, ge=0, le=600, description="hold each rate this long before the samples")
    verify_rates_dps: list[RateDps] = Field([], max_length=32, description="rates the fit never sees, turned "
                                            "both ways about each axis wherever the verification poses are taken")

    @field_validator("rates_dps", "verify_rates_dps")
    @classmethod
    def _distinct(cls, value: list[float]) -> list[float]:
        if len(set(value)) != len(value):
            raise ValueError("rates must be distinct")
        return value

    @field_validator("about")
    @classmethod
    def _distinct_axes(cls, value: list[str]) -> list[str]:
        if len(set(value)) != len(value):
            raise ValueError("fixture axes must be distinct")
        return value

    @model_validator(mode="after")
    def _verification_is_new(self) -> RateSteps:
        seen = set(self.rates_dps) & set(self.verify_rates_dps)
        if seen:
            raise ValueError(f"verify_rates_dps: {min(seen):g} °/s is a calibration rate; verification rates "
                             "must be ones the fit does not see")
        return self

    @property
    def steps_per_setpoint(self) -> int:
        return 2 * len(self.rates_dps) * len(self.about)

    @property
    def verification_steps(self) -> int:
        return 2 * len(self.verify_rates_dps) * len(self.about)


class NoiseRecord(StrictModel):
    """A still record at every calibration setpoint, for the Allan deviation: consecutive blocks of
    `acquisition.samples_per_pose` samples at one pose of the schedule, nothing moving."""

    duration_s: Real = Field(gt=0, le=86_400, description="how long (rounded up to whole blocks)")
    pose: Whole = Field(1, ge=1, le=10_000, description="the schedule's pose it is taken at")
