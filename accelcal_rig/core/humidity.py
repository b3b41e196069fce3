"""Dew point and relative humidity (Magnus form over water: Alduchov & Eskridge 1996, J. Appl. Meteor. 35,
601–609; a = 17.625, b = 243.04 °C, within 0.4 % of the reference formula from −40 to 50 °C). Chamber
controllers report relative humidity over water, so the same form turns a reading back into a dew point."""

from __future__ import annotations

import math

_A = 17.625
_B_C = 243.04


def _gamma(temperature_c: float) -> float:
    return _A * temperature_c / (_B_C + temperature_c)


def relative_humidity_pct(air_c: float, dew_point_c: float) -> float:
    """The relative humidity of air at `air_c` whose dew point is `dew_point_c`."""
    return 100.0 * math.exp(_gamma(dew_point_c) - _gamma(air_c))


#: Readings below this are taken as it: a controller shows dry purged air as 0 %, whose dew point is far below
#: anything in the chamber either way.
DRIEST_READING_PCT = 0.1


def dew_point_c(air_c: float, relative_humidity_pct: float) -> float:
    """The dew point of air at `air_c` with the given relative humidity (0 ≤ RH ≤ 100 %)."""
    if not 0.0 <= relative_humidity_pct <= 100.5:  # a sensor reads a little over 100 % in saturated air
        raise ValueError(f"relative humidity {relative_humidity_pct:g} % is not a reading")
    clamped = min(max(relative_humidity_pct, DRIEST_READING_PCT), 100.0)
    gamma = math.log(clamped / 100.0) + _gamma(air_c)
    return _B_C * gamma / (_A - gamma)
