"""How a campaign is fitted: the options every channel model's fit reads (a procedure's `fit:` section as the
campaign recorded it, command-line overrides applied: fit/recorded_options.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from accelcal_rig.fit.lm import FitMode, FreeParameters
from accelcal_rig.fit.thermal import OutOfRange

TemperatureModel = Literal["per-setpoint", "joint"]


@dataclass(frozen=True)
class FitOptions:
    mode: FitMode = "reference"
    degree: int = 3
    free: FreeParameters = "all"
    out_of_range: OutOfRange = "clamp"
    temperature_model: TemperatureModel = "per-setpoint"
    #: "on": the joint fit's bias carries ±h by each pose's direction of approach (a bidirectional ramp).
    hysteresis: str = "off"
