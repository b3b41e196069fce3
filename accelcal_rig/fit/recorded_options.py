"""The fit options a campaign file records from its procedure: written and read in this one place.

A campaign remembers how its procedure asked it to be fitted (root attributes `fit_mode`,
`polynomial_degree`, `fit_parameters`, `fit_out_of_range`, `fit_temperature_model`, `fit_hysteresis`), so `rig fit`,
`rig report` and the run's own fit stage agree; command-line options override single values.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, get_args

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.campaign_fit import FitOptions, TemperatureModel
from accelcal_rig.fit.lm import FitMode, FreeParameters
from accelcal_rig.fit.thermal import OutOfRange

#: FitOptions field → (campaign attribute, the values a fit accepts; None: a whole number).
_RECORDED: dict[str, tuple[str, tuple[str, ...] | None]] = {
    "mode": ("fit_mode", get_args(FitMode)),
    "degree": ("polynomial_degree", None),
    "free": ("fit_parameters", get_args(FreeParameters)),
    "out_of_range": ("fit_out_of_range", get_args(OutOfRange)),
    "temperature_model": ("fit_temperature_model", get_args(TemperatureModel)),
    "hysteresis": ("fit_hysteresis", ("off", "on")),
}
#: What the procedure says when it asks for no fit at all.
NO_FIT = "none"


def options_attrs(mode: str, degree: int, free: str, out_of_range: str, temperature_model: str,
                  hysteresis: bool = False) -> dict[str, Any]:
    """The attributes a campaign file records for a procedure's `fit` section."""
    values = {"mode": mode, "degree": degree, "free": free, "out_of_range": out_of_range,
              "temperature_model": temperature_model, "hysteresis": "on" if hysteresis else "off"}
    return {attribute: values[name] for name, (attribute, _) in _RECORDED.items()}


def requested_mode(attrs: Mapping[str, Any]) -> str:
    """The fit mode the campaign's procedure asked for: a FitMode, or `none` (measure only)."""
    return str(attrs.get("fit_mode", FitOptions.mode))


def recorded_options(attrs: Mapping[str, Any], source: str, **overrides: Any) -> FitOptions | None:
    """The options the campaign records, each override that is not None instead; None when the procedure
    asked for no fit and no mode is given. A value no fit accepts is refused naming `source` and the key."""
    if overrides.get("mode") is None and requested_mode(attrs) == NO_FIT:
        return None
    chosen: dict[str, Any] = {}
    for name, (attribute, accepted) in _RECORDED.items():
        given = overrides.get(name)
        value = given if given is not None else attrs.get(attribute, getattr(FitOptions, name))
        if accepted is None:
            try:
                value = int(value)
            except (TypeError, ValueError):
                raise ConfigError(f"{source}: {attribute}: {value!r} is not a whole number") from None
        elif str(value) not in accepted:
            raise ConfigError(f"{source}: {attribute}: {value!r} is not one of {', '.join(accepted)}")
        chosen[name] = value if accepted is None else str(value)
    return FitOptions(**chosen)
