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

BAROMETER = Channel(name="baro", quantity="pressure", unit="hPa", lsb_per_unit={1260: 4096.0}, range_codes={1260: 0},
                    code_bits=24, noise_density_micro_per_rthz=1.0)


def test_a_quantity_without_a_reference_is_refused_before_the_campaign(write, workdir: Path, monkeypatch) -> None:
    with_barometer = dataclasses.replace(ADXL355, channels=(*ADXL355.channels, BAROMETER))
    monkeypatch.setattr(preparation, "part", lambda name: with_barometer)
    with pytest.raises(ConfigError, match=r"sim.yaml:\d+: fixture.sensors\[0\].part: the ADXL355's baro channel "
                                          r"measures 'pressure', which no pose has a reference for"):
        preparation.prepare(write("tiny.yaml", TINY_PROCEDURE))


def test_a_magnetometer_on_a_rig_that_states_no_site_field_is_refused(workdir: Path, write) -> None:
    """The magnetometer's reference is the site's field: a rig config without `magnetic_field` cannot give it."""
    import yaml

    path = workdir / "sim.yaml"
    config = yaml.safe_load(path.read_text())
    config["fixture"]["sensors"][1]["part"] = "lis3mdl"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    with pytest.raises(ConfigError, match=r"sim.yaml:\d+: fixture.sensors\[1\].part: the LIS3MDL's mag channel "
                                          r"measures magnetic field, whose reference at each pose is the site's "
                                          r"magnetic field: state magnetic_field in "):
        preparation.prepare(write("tiny.yaml", TINY_PROCEDURE))
