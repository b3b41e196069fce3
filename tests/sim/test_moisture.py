"""The simulated chamber air's moisture: the room's dew point capped by cold air, frost coming back as it
warms faster than a fixture does, and the purge drying it."""

from __future__ import annotations

import pytest

from accelcal_rig.sim.moisture import ChamberMoisture


def ramp_air(t_s: float) -> float:
    """-40 °C until 1 h, then warming at 3 °C/min to 25 °C."""
    return min(25.0, -40.0 + max(0.0, t_s - 3600.0) * 0.05)


def test_cold_air_holds_no_more_than_its_temperature_and_the_room_comes_back_on_warming() -> None:
    moisture = ChamberMoisture(12.0, -40.0, 300.0, ramp_air)
    assert moisture.dew_point_c(3500.0) == pytest.approx(-40.0)  # capped by the cold air
    dew_at_10c = moisture.dew_point_c(3600.0 + 50.0 / 0.05)      # the air has reached 10 °C
    assert -5.0 < dew_at_10c < 10.0                               # lagging the air, but not far
    assert moisture.dew_point_c(3600.0 * 4) == pytest.approx(12.0, abs=0.01)


def test_the_purge_dries_the_air_toward_its_own_dew_point() -> None:
    moisture = ChamberMoisture(12.0, -40.0, 300.0, lambda t_s: 23.0)
    assert moisture.dew_point_c(0.0) == pytest.approx(12.0)
    moisture.set_purge(0.0, True)
    assert moisture.dew_point_c(300.0) == pytest.approx(-40.0 + 52.0 / 2.718281828, abs=0.5)  # one time constant
    assert moisture.dew_point_c(3600.0) == pytest.approx(-40.0, abs=0.01)
    moisture.set_purge(3600.0, False)
    assert moisture.dew_point_c(7200.0) == pytest.approx(12.0, abs=0.1)
