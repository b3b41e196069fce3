"""A rig config's `part:` reaches every place a part's facts matter: validation, the identity check, the
codes' scale in the file, and the simulated part of a dry run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.campaign import CampaignAborted
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from accelcal_rig.parts.adxl35x import ADXL357, ADXL359
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE


def with_parts(workdir: Path, parts: list[str], faults: dict | None = None) -> None:
    """The copied sim rig with these parts on its first sensors (and only those sensors)."""
    path = workdir / "sim.yaml"
    config = yaml.safe_load(path.read_text())
    config["fixture"]["sensors"] = [dict(s, part=p) for s, p in zip(config["fixture"]["sensors"], parts)]
    if faults:
        config.setdefault("simulation", {})["faults"] = faults
    path.write_text(yaml.safe_dump(config, sort_keys=False))


def test_a_dry_run_of_adxl357_and_adxl359_duts_simulates_those_parts(write, workdir: Path) -> None:
    with_parts(workdir, ["adxl357", "adxl359"])
    procedure = write("tiny.yaml", TINY_PROCEDURE.replace("range_g: 2", "range_g: 10"))
    output = workdir / "run.h5"
    run_campaign(prepare(procedure), output, dry_run=True, seed=3, overwrite=False)
    campaign = load_campaign(output)
    assert [(d["part"], campaign.channel_info(d["serial"], "accel").lsb) for d in campaign.header.duts] == [
        ("adxl357", 1 / 51_200), ("adxl359", 1 / 51_200)]
    for index, part in enumerate((ADXL357, ADXL359)):
        codes = np.stack([p.duts[index].channels["accel"].raw_codes for p in campaign.poses])        # (poses, samples, 3)
        norm_g = np.linalg.norm(codes.mean(axis=1), axis=1) * part.channel("accel").lsb(10)
        assert np.all(np.abs(norm_g - 1.0) < 0.05)                                  # 1 g at 51 200 LSB/g
        # Per-sample noise at 125 Hz: 80 µg/√Hz × √(π/2 · 125/4) ≈ 0.56 mg (an ADXL355 would give 0.18 mg).
        noise_g = codes.std(axis=1, ddof=1).mean() * part.channel("accel").lsb(10)
        assert noise_g == pytest.approx(80e-6 * np.sqrt(np.pi / 2 * 125 / 4), rel=0.25)
    # Both DUTs sit in the same air: the ADXL359's reading agrees with the ADXL357's only when its own
    # intercept (1852 LSB, not 1885) turns its codes into °C; with the other one it would read 3.6 °C high.
    temperatures = np.array([[d.temperature_c[0] for d in p.duts] for p in campaign.poses])
    assert np.all(np.abs(temperatures[:, 1] - temperatures[:, 0]) < 0.5)


def test_a_range_one_of_the_parts_lacks_is_refused_naming_the_sensor(write, workdir: Path) -> None:
    with_parts(workdir, ["adxl355", "adxl357"])
    with pytest.raises(ConfigError, match=r"tiny.yaml:6: acquisition.range_g: ±2 g is not a range of the ADXL357 "
                                          r"\(±10/20/40 g\): sensor ADX355-A002 of .*sim.yaml"):
        prepare(write("tiny.yaml", TINY_PROCEDURE))


def test_an_unknown_part_names_the_key_and_the_known_parts(write, workdir: Path) -> None:
    with_parts(workdir, ["adxl999"])
    with pytest.raises(ConfigError, match=r"sim.yaml:\d+: fixture.sensors\[0\].part: .*unknown part 'adxl999' "
                                          r"\(known: adxl355, adxl357, adxl359"):
        prepare(write("tiny.yaml", TINY_PROCEDURE))


def test_an_adxl355_where_an_adxl359_belongs_is_a_fault(write, workdir: Path) -> None:
    with_parts(workdir, ["adxl359"], faults={"sensor_wrong_id": "ADX355-A001"})
    procedure = write("tiny.yaml", TINY_PROCEDURE.replace("range_g: 2", "range_g: 20"))
    with pytest.raises(CampaignAborted, match=r"identity AD/1D/ED is not an ADXL359 \(AD/1D/E9\)"):
        run_campaign(prepare(procedure), workdir / "run.h5", dry_run=True, seed=1, overwrite=False)
