"""Dew point and relative humidity: the Magnus form against published values, and each the other's inverse."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.core.humidity import DRIEST_READING_PCT, dew_point_c, relative_humidity_pct


@pytest.mark.parametrize(("air_c", "rh_pct", "dew_c"), [
    (20.0, 50.0, 9.3),    # psychrometric tables: 9.3 °C
    (25.0, 60.0, 16.7),   # 16.7 °C
    (0.0, 80.0, -3.0),    # -3.0 °C (over water)
])
def test_dew_points_agree_with_psychrometric_tables(air_c: float, rh_pct: float, dew_c: float) -> None:
    assert dew_point_c(air_c, rh_pct) == pytest.approx(dew_c, abs=0.15)


def test_each_is_the_others_inverse_over_the_chamber_range() -> None:
    checked = 0
    for air_c in np.linspace(-40.0, 85.0, 11):
        for dew_c in np.linspace(-50.0, float(air_c), 7):
            rh_pct = relative_humidity_pct(air_c, dew_c)
            if rh_pct >= DRIEST_READING_PCT:  # drier than a sensor resolves: clamped, tested below
                assert dew_point_c(air_c, rh_pct) == pytest.approx(dew_c, abs=1e-9)
                checked += 1
    assert checked > 60


def test_saturated_air_and_dry_air_readings() -> None:
    assert dew_point_c(15.0, 100.0) == pytest.approx(15.0)
    assert dew_point_c(15.0, 100.4) == pytest.approx(15.0)  # a sensor a little over 100 % in saturated air
    assert dew_point_c(15.0, 0.0) == dew_point_c(15.0, 0.1) < -40.0  # purged air shown as 0 %
    with pytest.raises(ValueError, match="relative humidity 140 % is not a reading"):
        dew_point_c(15.0, 140.0)
