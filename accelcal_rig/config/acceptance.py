"""How a calibration is judged: verification poses the fit never sees, and the limits a DUT must meet to
pass."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, ModelWrapValidatorHandler, PrivateAttr, field_validator, model_validator

from accelcal_rig.config.bounds import Real, StrictModel, TemperatureC
from accelcal_rig.config.schedule import Schedule


class Verification(StrictModel):
    """Poses measured like the calibration's and kept out of the fit: every figure that says how good the
    calibration is comes from them."""

    schedule: Schedule
    at_setpoints: bool = Field(True, description="verification poses after the calibration poses at every "
                                                 "calibration setpoint")
    on_ramp: bool = Field(True, description="method ramp: also where the poses are taken on the ramp (false: "
                                            "only where the DUTs were soaked, at rest)")
    setpoints_c: list[TemperatureC] = Field(
        [], max_length=200, description="verification-only setpoints, between the calibration setpoints "
                                        "(soaked like them, only the verification poses measured)")

    @field_validator("setpoints_c")
    @classmethod
    def _distinct(cls, value: list[float]) -> list[float]:
        if len(set(value)) != len(value):
            raise ValueError("verification setpoints must be distinct")
        return value

    @model_validator(mode="after")
    def _somewhere(self) -> Verification:
        if not self.at_setpoints and not self.setpoints_c:
            raise ValueError("verification needs at_setpoints: true or setpoints_c")
        return self




#: A limit on a figure or a parameter: positive, at most what any channel model states as its largest.
Limit = Annotated[Real, Field(gt=0, le=1e6)]
#: The keys of `acceptance` that are not a channel's limits.
SHARED_KEYS = ("allow_partial", "decision_rule", "guard_band_factor")
#: The keys of an accelerometer's limits written before limits were keyed by channel (at the top of
#: `acceptance`), read as the limits of the channel that had them: `accel`.
_BEFORE_CHANNELS = ("max_verification_rmse_mg", "max_axis_error_mg", "max_drift_mg", "max_tilt_error_deg", "parameters")
_BEFORE_CHANNELS_CHANNEL = "accel"
#: Extra keys allowed, each checked as its annotation says (pydantic's `__pydantic_extra__`).
_OPEN = ConfigDict(extra="allow", frozen=True, allow_inf_nan=False)


class ParameterLimits(StrictModel):
    """Limits on a channel's calibration parameters at `at_c`, each keyed as its channel model names the kind of
    parameter it judges (an accelerometer's `bias_mg`, `scale_error_ppm`, `nonorthogonality_mrad`,
    `misalignment_mrad`; a gyroscope's `bias_dps`, `cross_axis_mrad`, …: docs/procedures.md); a limit left out is
    not judged."""

    model_config = _OPEN
    __pydantic_extra__: dict[str, Limit] = Field(init=False)  # type: ignore[assignment]

    at_c: TemperatureC = Field(25.0, description="temperature the parameters are judged at (inside the "
                                                 "calibrated range)")

    def limits(self) -> dict[str, float]:
        return dict(self.__pydantic_extra__ or {})


class ChannelLimits(StrictModel):
    """What one channel of every DUT must meet to PASS, keyed as its channel model names its figures (an
    accelerometer's `max_verification_rmse_mg`, a gyroscope's `max_verification_rmse_dps`, …: docs/procedures.md):
    figure limits judged on the verification records, parameter limits on the calibration at `parameters.at_c`."""

    model_config = _OPEN
    __pydantic_extra__: dict[str, Limit] = Field(init=False)  # type: ignore[assignment]

    parameters: ParameterLimits | None = None

    def figure_limits(self) -> dict[str, float]:
        return dict(self.__pydantic_extra__ or {})


def _before_channels_for_editors(schema: dict[str, Any]) -> None:
    """The accelerometer's limits at the top of `acceptance`, as `_before_channels` reads them, in the schema
    editors check files with (config/schemas.py)."""
    channel = schema.get("additionalProperties", {})
    for key in _BEFORE_CHANNELS:
        schema["properties"][key] = ({"type": "object", "description": "the accel channel's parameter limits"}
                                     if key == "parameters" else
                                     {"type": "number", "exclusiveMinimum": 0, "maximum": 1e6,
                                      "description": f"the {_BEFORE_CHANNELS_CHANNEL} channel's limit (written before "
                                                     f"limits were keyed by channel: {_BEFORE_CHANNELS_CHANNEL}.{key})"})
    schema["additionalProperties"] = channel


class Acceptance(StrictModel):
    """What a DUT's calibration must meet to PASS: each channel's limits under its channel's name
    (`acceptance: {accel: {…}, gyro: {…}}`), and how every figure is decided. A limit left out is not judged;
    the verification limits are judged on the verification records (a `verify:` section is needed for them).
    Limits written before they were keyed by channel (an accelerometer's at the top of `acceptance`) are the
    `accel` channel's."""

    model_config = ConfigDict(**_OPEN, json_schema_extra=_before_channels_for_editors)
    __pydantic_extra__: dict[Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,31}$")], ChannelLimits] = Field(
        init=False)  # type: ignore[assignment]

    allow_partial: bool = Field(False, description="a campaign that stopped before its last pose may pass")
    decision_rule: Literal["simple", "guarded"] | None = Field(
        None, description="how each figure's expanded uncertainty is taken into its verdict (ILAC-G8:09/2019): "
                          "simple acceptance, or guarded acceptance with a guard band of guard_band_factor × U; "
                          "stated on the certificate (none stated: simple, and said so)")
    guard_band_factor: Real = Field(1.0, gt=0, le=3, description="guarded acceptance: the guard band in "
                                                                 "expanded uncertainties (k = 2)")

    #: Whether the accelerometer's limits stood at the top of `acceptance` (how a message names them).
    _before_channels_written: bool = PrivateAttr(False)

    @model_validator(mode="wrap")
    @classmethod
    def _remember_layout(cls, data: Any, handler: ModelWrapValidatorHandler[Acceptance]) -> Acceptance:
        written = isinstance(data, dict) and any(key in data for key in _BEFORE_CHANNELS)
        model = handler(data)
        model._before_channels_written = written
        return model

    def written(self, channel: str, key: str) -> str:
        """A channel's limit as the procedure wrote it under `acceptance.`: `accel.max_drift_mg`, or
        `max_drift_mg` where the accelerometer's limits stand at the top."""
        return key if self._before_channels_written and channel == _BEFORE_CHANNELS_CHANNEL else f"{channel}.{key}"

    @model_validator(mode="before")
    @classmethod
    def _before_channels(cls, data: Any) -> Any:
        """An accelerometer's limits at the top of `acceptance` (before limits were keyed by channel) are the
        `accel` channel's."""
        if not isinstance(data, dict) or not any(key in data for key in _BEFORE_CHANNELS):
            return data
        if _BEFORE_CHANNELS_CHANNEL in data:
            raise ValueError(f"{', '.join(k for k in _BEFORE_CHANNELS if k in data)}: the {_BEFORE_CHANNELS_CHANNEL} "
                             f"channel's limits go under {_BEFORE_CHANNELS_CHANNEL}:, beside the others there")
        moved = {key: data[key] for key in _BEFORE_CHANNELS if key in data}
        return {**{k: v for k, v in data.items() if k not in moved}, _BEFORE_CHANNELS_CHANNEL: moved}

    @model_validator(mode="after")
    def _guard_band_guards(self) -> Acceptance:
        if self.guard_band_factor != 1.0 and self.decision_rule != "guarded":
            raise ValueError("acceptance.guard_band_factor is the guard band of decision_rule: guarded")
        return self

    @property
    def channels(self) -> dict[str, ChannelLimits]:
        """Each channel's limits by the channel's name."""
        return dict(self.__pydantic_extra__ or {})

    def states_limits(self) -> bool:
        """Whether any limit is stated (a rule without one judges nothing)."""
        return any(limits.figure_limits() or limits.parameters is not None for limits in self.channels.values())

    def verification_limits(self) -> list[str]:
        """Every figure limit (judged on verification records) as the procedure wrote it (`written`)."""
        return [self.written(channel, key) for channel, limits in self.channels.items() for key in limits.figure_limits()]
