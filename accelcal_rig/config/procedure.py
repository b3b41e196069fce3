"""The procedure: what a campaign does (setpoints, soak criterion, pose schedule, acquisition, fit)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import ConfigDict, Field, field_validator, model_validator

from accelcal_rig.config.acceptance import Acceptance, Verification
from accelcal_rig.config.bounds import STRICT, Real, StrictModel, TemperatureC, TemperatureSpanC, Whole
from accelcal_rig.config.rate_steps import NoiseRecord, RateSteps
from accelcal_rig.config.schedule import MAX_SCHEDULE_POSES, Schedule

#: Most temperature polls a campaign's ramp and soak deadlines allow (`rig plan` plays them all).
MAX_POLLS = 200_000
#: Most poses a plan may hold (setpoints × schedule, or a cool-down's records).
MAX_PLAN_POSES = 20_000
#: The early check's default limits (docs/procedures.md, "The early check": healthy and faulty DUTs measured).
EARLY_RESIDUAL_RATIO_LIMIT = 20.0
EARLY_DIRECTION_LIMIT_DEG = 10.0
EARLY_AXIS_GAIN_LIMIT = 0.5



class SoakCriterion(StrictModel):
    """When the DUTs count as thermally stable at a setpoint (every wait has a deadline: `timeout_min`).

    `criterion: band` (the paper's way): each DUT's readings span at most `band_c` over the trailing window;
    with more polls or more DUTs the noise makes a span wider, so the soak lasts longer. `criterion: settling`:
    a settling curve fitted to each DUT's readings over the window predicts how much it will still change and
    how fast it changes now; stable once both bounds (k = 2) are within `settle_c` and `max_rate_c_per_min`.
    More polls only tighten the bounds (engine/soak.py, docs/procedures.md).
    """

    criterion: Literal["band", "settling"] = Field("band", description="band: readings within band_c over "
                                                   "the window; settling: a fitted settling curve's prediction")
    min_dwell_min: Real = Field(30.0, ge=0, le=2880, description="least time at setpoint before stability counts")
    window_min: Real = Field(10.0, gt=0, le=1440, description="trailing window over which stability is judged")
    band_c: TemperatureSpanC = Field(0.3, description="max−min of each DUT's own temperature over the window")
    chamber_tolerance_c: TemperatureSpanC = Field(1.0, description="chamber air within this of the setpoint")
    settle_c: Real = Field(0.1, gt=0, le=10, description="criterion settling: most change still to come (k = 2) "
                                                         "of each DUT's temperature")
    max_rate_c_per_min: Real = Field(0.02, gt=0, le=10, description="criterion settling: fastest each DUT's "
                                     "temperature may still move (k = 2), °C/min")
    time_constant_max_min: Real = Field(60.0, gt=0, le=1440, description="criterion settling: the slowest "
                                        "settling time constant fitted (the fixture's, with margin)")
    poll_s: Real = Field(10.0, ge=1, le=600, description="temperature polling interval")
    timeout_min: Real = Field(240.0, gt=0, le=2880, description="soak deadline, counted from reaching the setpoint")
    on_timeout: Literal["abort", "skip", "proceed"] = Field(
        "abort", description="a soak not stable by its deadline: abort the campaign, skip the setpoint "
                             "(recorded; a resume tries it again), or measure its poses anyway with a warning")
    ramp_timeout_factor: Real = Field(
        2.0, ge=1, le=10, description="ramp deadline = factor × |Δ| / rig ramp rate + ramp_timeout_margin_min"
    )
    ramp_timeout_margin_min: Real = Field(15.0, ge=0, le=1440)

    @model_validator(mode="after")
    def _fits_in_timeout(self) -> SoakCriterion:
        if max(self.min_dwell_min, self.window_min) > self.timeout_min:
            raise ValueError("timeout_min must be at least min_dwell_min and window_min")
        if self.criterion == "settling" and self.window_min * 60.0 < 5 * self.poll_s:
            raise ValueError(f"criterion settling judges at least 5 polls in the window: window_min "
                             f"{self.window_min:g} is {self.window_min * 60 / self.poll_s:.1f} polls of {self.poll_s:g} s")
        if self.timeout_min * 60.0 / self.poll_s > MAX_POLLS:
            raise ValueError(f"timeout_min / poll_s: a soak would be polled {self.timeout_min * 60 / self.poll_s:.0f} "
                             f"times (at most {MAX_POLLS}): poll less often or shorten the timeout")
        return self


#: The channel whose range acquisition took as `range_g` before ranges were keyed by channel, and its default.
_RANGE_G_CHANNEL, _RANGE_G_DEFAULT = "accel", 2
#: Each channel's key before ranges were keyed by channel (read as `ranges.<channel>`).
BEFORE_RANGES = {"range_g": "accel", "range_dps": "gyro"}


def _setpoint_range_for_editors(schema: dict[str, Any]) -> None:
    """`setpoints_c` as a list, or the `{from_c, to_c, step_c}` shorthand `_setpoint_range` reads (for editors)."""
    listed = dict(schema)
    schema.clear()
    schema["anyOf"] = [listed, {"type": "object", "additionalProperties": False,
                                "required": ["from_c", "to_c", "step_c"],
                                "properties": {key: {"type": "number"} for key in ("from_c", "to_c", "step_c")},
                                "description": "an evenly stepped list: from from_c to to_c in steps of step_c"}]


def _before_ranges_for_editors(schema: dict[str, Any]) -> None:
    """The keys `_before_ranges` reads, in the schema editors check files with (config/schemas.py)."""
    for key, channel in BEFORE_RANGES.items():
        schema["properties"][key] = {"type": "number", "exclusiveMinimum": 0, "maximum": 1e6,
                                     "description": f"± full scale of the {channel} channel (written before ranges were "
                                                    f"keyed by channel: ranges.{channel})"}


class Acquisition(StrictModel):
    """How each pose is measured."""

    model_config = ConfigDict(**STRICT, json_schema_extra=_before_ranges_for_editors)

    samples_per_pose: Whole = Field(200, ge=2, le=100_000)
    ranges: dict[Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,31}$")], Annotated[Real, Field(gt=0, le=1e6)]] = Field(
        {_RANGE_G_CHANNEL: _RANGE_G_DEFAULT}, max_length=16,
        description="± full scale of each channel by the channel's name, in its unit (accel: 2 g, gyro: 2000 °/s), one "
                    "of every DUT part's ranges for it; accel 2 g unless given")
    fine_ranges: dict[Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,31}$")], Annotated[Real, Field(gt=0, le=1e6)]] = (
        Field({}, max_length=16,
              description="a finer ± full scale per channel (gyro: 250 °/s) for the steps whose readings it holds with "
                          "room (engine/step_ranges.py: a gyroscope's at rest, in noise records and at rate steps up to "
                          "80 % of it); every other step at `ranges`. The calibration holds the scale of each range"))
    odr_hz: Real = Field(125.0, gt=0, le=100_000,
                         description="output data rate; a DUT part without it runs at its next faster rate")
    settle_s: Real = Field(5.0, ge=0, le=3600, description="wait after the turntable is in position")

    def block_s(self, rates_hz: Sequence[float] = ()) -> float:
        """How long a pose's samples take: at the slowest of the DUTs' rates `rates_hz`, at `odr_hz` when they are
        not known (no DUT runs slower than that)."""
        return self.samples_per_pose / min(rates_hz, default=self.odr_hz)

    @model_validator(mode="before")
    @classmethod
    def _before_ranges(cls, data: Any) -> Any:
        """`range_g` and `range_dps` (before ranges were keyed by channel) are `ranges.accel` and `ranges.gyro`;
        the accelerometer's range is 2 g unless given."""
        if not isinstance(data, dict):
            return data
        ranges = data.get("ranges", {})
        if not isinstance(ranges, dict):
            return data
        ranges = dict(ranges)
        for key, channel in BEFORE_RANGES.items():
            if key in data:
                if channel in ranges:
                    raise ValueError(f"{key} and ranges.{channel} both give the {channel} channel's range: keep one")
                ranges[channel] = data[key]
        ranges.setdefault(_RANGE_G_CHANNEL, _RANGE_G_DEFAULT)
        return {**{k: v for k, v in data.items() if k not in BEFORE_RANGES}, "ranges": ranges}


class FitOptions(StrictModel):
    """How the campaign's data will be fitted (paper §3)."""

    temperature_model: Literal["per-setpoint", "joint"] = Field(
        "per-setpoint", description="per-setpoint: LM at each setpoint, then polynomials (Eq. 8); joint: the "
                                    "polynomials fitted to every pose at its own temperature (the ramp method)")
    mode: Literal["reference", "norm-only", "none"] = Field(
        "reference", description="none: measure only (a tilt check, a cool-down), no calibration at the end")
    polynomial_degree: Whole = Field(3, ge=0, le=6)
    parameters: Literal["all", "bias-scale"] = "all"
    out_of_range: Literal["clamp", "extrapolate"] = "clamp"
    hysteresis: bool = Field(False, description="joint fit of a bidirectional ramp: a bias ±h per axis by the "
                             "direction each pose was approached from and c × its rate of change; the "
                             "calibration is the sensor at rest, 2h and c are reported")


class SimulatedEffects(StrictModel):
    """Effects of real sensors that Eq. 1 does not contain, for dry runs only (off by default).

    They show how the fit copes with reality: a calibration on such a sensor cannot reach the noise floor.
    """

    hysteresis_mg: Real = Field(0.0, ge=0, le=50, description="bias difference between approaching a "
                                "temperature from below and from above")
    hysteresis_span_c: Real = Field(0.0, ge=0, le=100, description="the travel over which the hysteresis swings "
                                    "from one side to the other (0: at once)")
    hysteresis_time_constant_h: Real | None = Field(None, gt=0, le=1000, description="the hysteresis relaxes "
                                                    "towards none with this time constant (unset: never)")
    rate_bias_mg_per_c_per_min: Real = Field(0.0, ge=0, le=50, description="bias per °C/min of the DUT's own "
                                             "temperature change (package stress in a ramp), ± per axis and DUT")
    rate_scale_ppm_per_c_per_min: Real = Field(0.0, ge=0, le=10_000, description="scale factor change per "
                                               "°C/min, ± per axis and DUT")
    nonlinearity_mg_per_g2: Real = Field(0.0, ge=0, le=50, description="square-law term per axis, ± per DUT")


class Cooldown(StrictModel):
    """Free cool-down validation (paper §4.3, Fig. 11): after the soak at the procedure's one setpoint,
    hold one pose, let the chamber go (switched off, or set to ambient) and record while the DUTs cool."""

    pose: Whole = Field(1, ge=1, le=MAX_SCHEDULE_POSES, description="pose number of the schedule to hold")
    chamber: Literal["power-off", "ambient"] = Field(
        "power-off", description="power-off: the chamber switched off (its power event); ambient: its set point "
                                 "to ambient_c")
    ambient_c: TemperatureC = Field(23.0, description="set point for chamber: ambient")
    record_every_s: Real = Field(60.0, gt=0, le=3600, description="one block of samples this often")
    duration_min: Real = Field(240.0, gt=0, le=7 * 24 * 60, description="how long to record")


class RampMethod(StrictModel):
    """Poses measured while the chamber ramps slowly, instead of soaking at each setpoint (paper §4.3 names
    both methods). After a soak at the first setpoint the chamber setpoint moves at `rate_c_per_min`
    towards the last; each setpoint's poses start once the ramp is half-way from the previous setpoint."""

    rate_c_per_min: Real = Field(ge=0.01, le=10, description="the software ramp of the chamber setpoint")
    update_s: Real = Field(30.0, ge=1, le=600, description="how often the chamber setpoint is moved on")
    bidirectional: bool = Field(False, description="after a soak at the last setpoint, ramp back towards the "
                                "first, the poses taken again half-way between the setpoints: every band "
                                "measured warming and cooling, so rate and lag errors cancel in the joint fit "
                                "and the hysteresis shows")


class Frost(StrictModel):
    """Frost and condensation on a cold fixture: dry air while cold, and no poses below the dew point.

    Coming up from the cold, the DUTs lag the chamber air, and the air's moisture (the frost coming off
    the evaporator, the room's air) condenses on anything colder than its dew point.
    """

    purge_below_c: TemperatureC | None = Field(None, description="hold the chamber's dry-air purge on while the "
                                               "setpoint is below this (off at and above it)")
    dew_point_margin_c: Real | None = Field(None, ge=0, le=50, description="after a warming step, poses wait "
                                            "until every DUT is this far above the chamber air's dew point")
    dew_point_timeout_min: Real = Field(60.0, gt=0, le=1440, description="longest wait for that margin")


class EarlyCheck(StrictModel):
    """After each soaked setpoint's calibration poses, every DUT against its own fit of them: a loose mount, a
    DUT mounted in another orientation or a dead axis is an event at the first setpoint, not a failed fit after
    the last (docs/procedures.md, "The early check"; the defaults are measured there)."""

    action: Literal["warn", "drop", "none"] = Field("warn", description="warn: an event (log, rig status, "
                                                   "notification); drop: that, and the DUT is left out of the fit "
                                                   "(measured on); none: no check")
    residual_ratio_limit: Real = Field(EARLY_RESIDUAL_RATIO_LIMIT, gt=1, le=1e6, description="a DUT whose own fit's "
                                       "residuals exceed this many times its noise (√χ²_red) moved between poses")
    direction_limit_deg: Real = Field(EARLY_DIRECTION_LIMIT_DEG, gt=0, le=180, description="a DUT whose measured "
                                      "gravity directions are turned more than this from its mount's is mounted "
                                      "otherwise than configured")
    axis_gain_limit: Real = Field(EARLY_AXIS_GAIN_LIMIT, gt=0, lt=1, description="an axis responding less than "
                                  "this (g per g of specific force across the poses) is dead")


class Procedure(StrictModel):
    """A whole campaign. Setpoints run in the order given."""

    name: str = Field(min_length=1, max_length=128, pattern=r"^[A-Za-z0-9_.-]+$")
    version: str = Field("", max_length=32, pattern=r"^[A-Za-z0-9_.+-]*$", description="the procedure's version "
                         "(its revision under the lab's document control), quoted text; empty: certificates say it "
                         "is not stated")
    description: str = Field("", max_length=10_000)
    rig: str = Field(min_length=1, max_length=4096, pattern=r"^[^\x00]+$",
                     description="rig config path, relative to this file")
    setpoints_c: list[TemperatureC] = Field(min_length=1, max_length=200, json_schema_extra=_setpoint_range_for_editors)
    soak: SoakCriterion = SoakCriterion()
    schedule: Schedule
    acquisition: Acquisition = Acquisition()
    safe_setpoint_c: TemperatureC | None = Field(None, description="overrides the rig's chamber.safe_setpoint_c")
    fit: FitOptions = FitOptions()
    cooldown: Cooldown | None = Field(None, description="record a free cool-down instead of the schedule's poses")
    method: Literal["soak", "ramp"] = Field("soak", description="soak at every setpoint, or measure while ramping")
    ramp: RampMethod | None = None
    simulation: SimulatedEffects = SimulatedEffects()
    verify: Verification | None = Field(None, description="verification poses the fit never sees")
    acceptance: Acceptance = Acceptance()
    frost: Frost = Field(Frost(), description="dry-air purge and the dew point requirement")
    rates: RateSteps | None = Field(None, description="a gyroscope's rate steps at every setpoint (a rate table); "
                                                      "the ramp method: in every band, each way")
    noise: NoiseRecord | None = Field(None, description="a still record at every setpoint where the DUTs are soaked "
                                                        "(Allan deviation)")
    early_check: EarlyCheck = Field(EarlyCheck(), description="every DUT checked after each setpoint's poses")

    @model_validator(mode="after")
    def _gyroscope_steps_fit(self) -> Procedure:
        if self.rates is None and self.noise is None:
            return self
        if self.cooldown is not None:
            raise ValueError("rates and noise are a calibration's steps: a cool-down procedure has neither")
        if self.rates is not None and self.rates.verify_rates_dps and self.verify is None:
            raise ValueError("rates.verify_rates_dps are measured where the verification poses are: add a verify: "
                             "section")
        if self.noise is not None and self.noise.pose > self.schedule.size:
            raise ValueError(f"noise.pose: pose {self.noise.pose} asked for, the schedule has {self.schedule.size}")
        return self

    def noise_blocks(self) -> int:
        """Blocks of `samples_per_pose` samples a noise record takes at each setpoint."""
        if self.noise is None:
            return 0
        block_s = self.acquisition.block_s()
        return max(1, int(np.ceil(self.noise.duration_s / block_s - 1e-9)))

    @model_validator(mode="after")
    def _ramp_fits(self) -> Procedure:
        if self.method == "soak":
            if self.ramp is not None:
                raise ValueError("ramp settings need method: ramp")
            if self.fit.hysteresis:
                raise ValueError("fit.hysteresis needs poses approached from both sides: method: ramp with "
                                 "ramp.bidirectional: true")
            return self
        if self.ramp is None:
            raise ValueError("method: ramp needs ramp.rate_c_per_min")
        if self.cooldown is not None:
            raise ValueError("a cool-down procedure cannot use method: ramp")
        steps = np.diff(self.setpoints_c)
        if len(steps) == 0 or not (np.all(steps > 0) or np.all(steps < 0)):
            raise ValueError("method: ramp needs at least two setpoints, all rising or all falling")
        if self.fit.mode != "none" and self.fit.temperature_model != "joint":
            raise ValueError("a ramp campaign's poses spread over each setpoint's temperatures: set "
                             "fit.temperature_model: joint")
        if self.fit.hysteresis and not self.ramp.bidirectional:
            raise ValueError("fit.hysteresis needs poses approached from both sides: ramp.bidirectional: true")
        return self

    @model_validator(mode="after")
    def _cooldown_fits(self) -> Procedure:
        if self.cooldown is not None:
            if len(self.setpoints_c) != 1:
                raise ValueError("a cool-down procedure has one setpoint: the temperature it cools from")
            block_s = self.acquisition.settle_s + self.acquisition.block_s()
            if self.cooldown.record_every_s < block_s:
                raise ValueError(f"cooldown.record_every_s must be at least one record's {block_s:g} s (settle "
                                 "and samples)")
            if self.cooldown.duration_min * 60.0 / self.cooldown.record_every_s >= MAX_PLAN_POSES:
                raise ValueError(f"cooldown.duration_min / record_every_s: more than {MAX_PLAN_POSES} records")
        return self

    @model_validator(mode="after")
    def _verification_fits(self) -> Procedure:
        verify = self.verify
        if verify is None:
            needed = self.acceptance.verification_limits()
            if needed:
                raise ValueError(f"acceptance.{needed[0]} is judged on verification records: add a verify: section")
            return self
        if self.cooldown is not None:
            raise ValueError("a cool-down procedure has no verification poses (verify)")
        if verify.setpoints_c and self.method == "ramp":
            raise ValueError("verify.setpoints_c: the ramp passes every temperature; verify at_setpoints instead")
        low, high = min(self.setpoints_c), max(self.setpoints_c)
        for setpoint in verify.setpoints_c:
            if setpoint in self.setpoints_c:
                raise ValueError(f"verify.setpoints_c: {setpoint:g} °C is a calibration setpoint (verify there "
                                 "with at_setpoints)")
            if not low < setpoint < high:
                raise ValueError(f"verify.setpoints_c: {setpoint:g} °C is outside the calibrated range "
                                 f"{low:g} … {high:g} °C")
        return self

    @model_validator(mode="after")
    def _parameters_judged_inside(self) -> Procedure:
        low, high = min(self.setpoints_c), max(self.setpoints_c)
        for channel, limits in self.acceptance.channels.items():
            if limits.parameters is not None and not low <= limits.parameters.at_c <= high:
                raise ValueError(f"acceptance.{self.acceptance.written(channel, 'parameters')}.at_c: "
                                 f"{limits.parameters.at_c:g} °C is outside the "
                                 f"calibrated range {low:g} … {high:g} °C")
        return self

    def verification_temperatures(self) -> int:
        """How many temperatures the verification records are taken at (0 without a verify: section)."""
        if self.verify is None:
            return 0
        return len(self.verify.setpoints_c) + (self.verified_bands() if self.verify.at_setpoints else 0)

    @model_validator(mode="after")
    def _plan_size(self) -> Procedure:
        poses = self.bands() * self.schedule_size() + self.verification_poses()
        if self.cooldown is None and poses > MAX_PLAN_POSES:
            raise ValueError(f"{self.bands()} setpoints × {self.schedule_size()} poses and "
                             f"{self.verification_poses()} verification poses = {poses} poses: a campaign holds "
                             f"at most {MAX_PLAN_POSES}")
        return self

    def schedule_size(self) -> int:
        """Records of one calibration setpoint: the schedule's poses, a gyroscope's rate steps and noise
        record."""
        rates = self.rates.steps_per_setpoint if self.rates is not None else 0
        return self.schedule.size + rates + self.noise_blocks()

    def bands(self) -> int:
        """Setpoints whose poses are measured: each calibration setpoint, and a bidirectional ramp's way back
        half-way between them."""
        n = len(self.setpoints_c)
        return 2 * n - 1 if self.ramp is not None and self.ramp.bidirectional else n

    def verification_poses(self) -> int:
        """Verification poses of the whole campaign."""
        verify = self.verify
        if verify is None:
            return 0
        setpoints = len(verify.setpoints_c) + (self.verified_bands() if verify.at_setpoints else 0)
        rates = self.rates.verification_steps if self.rates is not None else 0
        return setpoints * (verify.schedule.size + rates)

    def verified_bands(self) -> int:
        """Bands whose verification poses `verify.at_setpoints` measures: all, or with `verify.on_ramp: false`
        a ramp's soaked ones only (its first setpoint and, bidirectional, its turn; one-way, its last)."""
        if self.verify is None or self.ramp is None or self.verify.on_ramp:
            return self.bands()
        return 2

    @field_validator("version", mode="before")
    @classmethod
    def _version_as_written(cls, value: object) -> object:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            raise ValueError(f"write it as quoted text, version: \"{value}\" (a bare number loses what a version "
                             "means: 1.10 would read 1.1)")
        return value

    @field_validator("setpoints_c", mode="before")
    @classmethod
    def _expand_range(cls, value: object) -> object:
        """Accept `{from_c, to_c, step_c}` as a shorthand for an evenly stepped list."""
        if not isinstance(value, dict):
            return value
        unknown = set(value) - {"from_c", "to_c", "step_c"}
        missing = {"from_c", "to_c", "step_c"} - set(value)
        if unknown or missing:
            raise ValueError("a setpoint range needs exactly the keys from_c, to_c and step_c")
        given = [value[k] for k in ("from_c", "to_c", "step_c")]
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in given):
            raise ValueError("from_c, to_c and step_c must be numbers, written without quotes")
        start, stop, step = (float(v) for v in given)
        if not all(np.isfinite([start, stop, step])) or max(abs(start), abs(stop)) > 1000:
            raise ValueError("from_c, to_c and step_c must be finite temperatures")
        if abs(step) < 1e-3 or (stop - start) / step < 0:
            raise ValueError("step_c must be at least 0.001 °C and lead from from_c to to_c")
        count = int(np.floor((stop - start) / step + 1e-9)) + 1
        if count > 200:
            raise ValueError("a setpoint range may hold at most 200 setpoints")
        return [round(start + i * step, 9) for i in range(count)]

    @field_validator("setpoints_c")
    @classmethod
    def _distinct(cls, value: list[float]) -> list[float]:
        if len(set(value)) != len(value):
            raise ValueError("setpoints must be distinct")
        return value
