"""Number types with units and the ranges a real rig can have: a value outside is a config error naming
its key, never a campaign that runs for a century or an estimate that never ends."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

#: Every config model: unknown keys and non-finite numbers (.inf, .nan) are refused.
STRICT = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class StrictModel(BaseModel):
    """The base of every model read from a file: see STRICT."""

    model_config = STRICT

#: A temperature a calibration chamber can hold, °C.
TemperatureC = Annotated[float, Field(ge=-100.0, le=300.0)]
#: A temperature difference, °C.
TemperatureSpanC = Annotated[float, Field(gt=0.0, le=50.0)]
#: A turntable or mount angle, degrees.
AngleDeg = Annotated[float, Field(ge=-3600.0, le=3600.0)]
#: A wire timeout, s.
TimeoutS = Annotated[float, Field(ge=0.001, le=60.0)]
#: A serial line's speed, baud.
Baudrate = Annotated[int, Field(ge=50, le=20_000_000)]
