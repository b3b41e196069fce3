"""A part (a plug-in's) measuring a quantity no pose has a reference for is refused before anything moves,
in one line naming the rig config's key, not at the first pose after hours of soak."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from accelcal_rig.engine import preparation
from accelcal_rig.errors import ConfigError
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.parts.part import Channel
from tests.conftest import TINY_PROCEDURE

COMPASS = Channel(name="mag", quantity="magnetic field", unit="uT", lsb_per_unit={4900: 6.6}, range_codes={4900: 0},
                  code_bits=16, noise_density_micro_per_rthz=1.0)


def test_a_quantity_without_a_reference_is_refused_before_the_campaign(write, workdir: Path, monkeypatch) -> None:
    with_compass = dataclasses.replace(ADXL355, channels=(*ADXL355.channels, COMPASS))
    monkeypatch.setattr(preparation, "part", lambda name: with_compass)
    with pytest.raises(ConfigError, match=r"sim.yaml:\d+: fixture.sensors\[0\].part: the ADXL355's mag channel "
                                          r"measures 'magnetic field', which no pose has a reference for"):
        preparation.prepare(write("tiny.yaml", TINY_PROCEDURE))
