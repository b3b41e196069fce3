"""How a calibration is judged: verification poses the fit never sees, and the limits a DUT must meet to
pass."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator, model_validator

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




class ParameterLimits(StrictModel):
    """Limits on the calibration's parameters at `at_c`, e.g. the datasheet's zero-g offset; a limit left
    out is not judged."""

    at_c: TemperatureC = Field(25.0, description="temperature the parameters are judged at (inside the "
                                                 "calibrated range)")
    bias_mg: Real | None = Field(None, gt=0, le=1000, description="|bias| of each axis")
    scale_error_ppm: Real | None = Field(None, gt=0, le=1e6, description="|scale − 1| of each axis")
    nonorthogonality_mrad: Real | None = Field(None, gt=0, le=1000, description="|each non-orthogonality|")
    misalignment_mrad: Real | None = Field(None, gt=0, le=1000, description="|each misalignment| (reference "
                                                                             "mode only)")


class GyroParameterLimits(StrictModel):
    """Limits on a gyroscope's calibration at `at_c` (a data sheet's figures); a limit left out is not judged."""

    at_c: TemperatureC = Field(25.0, description="temperature the parameters are judged at (inside the "
                                                 "calibrated range)")
    bias_dps: Real | None = Field(None, gt=0, le=1000, description="|bias| of each axis, the Earth's rate taken "
                                                                  "out as the calibration states")
    scale_error_ppm: Real | None = Field(None, gt=0, le=1e6, description="|scale − 1| of each axis")
    cross_axis_mrad: Real | None = Field(None, gt=0, le=1000, description="|each cross-axis term| of K")
    gsens_dps_per_g: Real | None = Field(None, gt=0, le=1000, description="|each g-sensitivity term|")


class GyroAcceptance(StrictModel):
    """What a DUT's gyroscope must meet to PASS; the verification limits are judged on the rate steps and
    poses the fit never saw (`rates.verify_rates_dps`, `verify:`)."""

    max_verification_rmse_dps: Real | None = Field(None, gt=0, le=10_000, description="RMS axis error of the "
                                                   "compensated verification rate steps against their references")
    max_axis_error_dps: Real | None = Field(None, gt=0, le=10_000, description="largest axis error of a "
                                            "compensated verification rate step")
    max_scale_error_ppm: Real | None = Field(None, gt=0, le=1e6, description="largest relative error along the "
                                             "turning axis at the verification rates")
    max_rest_error_dps: Real | None = Field(None, gt=0, le=10_000, description="RMS axis error of the compensated "
                                            "verification poses (at rest: the bias left)")
    parameters: GyroParameterLimits | None = None

    def verification_limits(self) -> list[str]:
        names = ["max_verification_rmse_dps", "max_axis_error_dps", "max_scale_error_ppm", "max_rest_error_dps"]
        return [n for n in names if getattr(self, n) is not None]


class Acceptance(StrictModel):
    """What a DUT's calibration must meet to PASS; each limit left out is not judged. The verification
    limits are judged on the verification poses (a `verify:` section is needed for them)."""

    max_verification_rmse_mg: Real | None = Field(None, gt=0, le=1000, description="Eq. 9 |g| RMSE")
    max_axis_error_mg: Real | None = Field(None, gt=0, le=1000, description="largest per-axis error of the "
                                           "compensated vector against the reference gravity")
    max_drift_mg: Real | None = Field(None, gt=0, le=1000, description="residual zero-g drift per axis over "
                                      "the verification temperatures (max − min)")
    max_tilt_error_deg: Real | None = Field(None, gt=0, le=90, description="largest Eq. 10 pitch or roll error")
    parameters: ParameterLimits | None = None
    gyro: GyroAcceptance | None = Field(None, description="a gyroscope's limits (a procedure with rates:)")
    allow_partial: bool = Field(False, description="a campaign that stopped before its last pose may pass")
    decision_rule: Literal["simple", "guarded"] | None = Field(
        None, description="how each figure's expanded uncertainty is taken into its verdict (ILAC-G8:09/2019): "
                          "simple acceptance, or guarded acceptance with a guard band of guard_band_factor × U; "
                          "stated on the certificate (none stated: simple, and said so)")
    guard_band_factor: Real = Field(1.0, gt=0, le=3, description="guarded acceptance: the guard band in "
                                                                 "expanded uncertainties (k = 2)")

    @model_validator(mode="after")
    def _guard_band_guards(self) -> Acceptance:
        if self.guard_band_factor != 1.0 and self.decision_rule != "guarded":
            raise ValueError("acceptance.guard_band_factor is the guard band of decision_rule: guarded")
        return self

    def states_limits(self) -> bool:
        """Whether any limit is stated (a rule without one judges nothing)."""
        return bool(self.verification_limits()) or self.parameters is not None or self.gyro is not None

    def verification_limits(self) -> list[str]:
        """The keys of the limits that need verification poses."""
        names = ["max_verification_rmse_mg", "max_axis_error_mg", "max_drift_mg", "max_tilt_error_deg"]
        return [n for n in names if getattr(self, n) is not None]
