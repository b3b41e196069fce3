"""Dew point, frost point and relative humidity (Magnus forms of Alduchov & Eskridge 1996, J. Appl. Meteor.
35, 601–609: over water a = 17.625, b = 243.04 °C, c = 6.1094 hPa, within 0.4 % of the reference formula
from −40 to 50 °C; over ice a = 22.587, b = 273.86 °C, c = 6.1121 hPa). Chamber controllers report
relative humidity over water, so the water form turns a reading back into a dew point; below 0 °C a cold
surface collects frost first, at the frost point, which is above the dew point."""

from __future__ import annotations

import math

_A = 17.625
_B_C = 243.04
_C_HPA = 6.1094
_A_ICE = 22.587
_B_ICE_C = 273.86
_C_ICE_HPA = 6.1121


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


def frost_point_c(dew_point_c: float) -> float:
    """The temperature at which air with this dew point (over water) is saturated over ice."""
    vapour_hpa = _C_HPA * math.exp(_gamma(dew_point_c))
    gamma = math.log(vapour_hpa / _C_ICE_HPA)
    return _B_ICE_C * gamma / (_A_ICE - gamma)


def condensation_point_c(dew_point_c: float) -> float:
    """Where a cold surface first collects water: the dew point, or below 0 °C the (higher) frost point."""
    return dew_point_c if dew_point_c >= 0.0 else frost_point_c(dew_point_c)
