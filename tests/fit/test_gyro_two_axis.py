"""A gyroscope calibrated on a two-axis rate table (configs/sim-imu-2axis.yaml: a horizontal outer axis and a
turntable axis square to it): the plan turns fixture x and y on the outer axis, z on the inner one; gravity turns
through the outer axis's rate steps, and what the fit sees of it is its average over each record. The fit
recovers each DUT's hidden gyroscope as well as on the three-axis table. Where no axis turns a fixture axis,
the plan refuses in one line saying which directions each rate axis reaches."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.assembly import run_campaign
from accelcal_rig.config.rate_steps import RateSteps
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save
from accelcal_rig.plan.gyro_steps import NoRateAxis, spins
from accelcal_rig.plan.kinematics import TurntableKinematics
from accelcal_rig.plan.steps import RateStep
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO
from tests.fit.test_gyro_fit import PROCEDURE, gyro_records

RIG = REPO / "configs" / "sim-imu-2axis.yaml"
#: The small IMU procedure at two setpoints, verified between them.
TWO_AXIS = {**PROCEDURE, "rig": str(RIG), "setpoints_c": [0, 40],
            "verify": {"schedule": {"kind": "sphere", "count": 6}, "at_setpoints": False, "setpoints_c": [20]}}


def _rig(**axes: dict) -> RigConfig:
    """The two-axis rig with its axes changed."""
    data = yaml.safe_load(RIG.read_text())
    for axis in data["turntable"]["axes"]:
        axis.update(axes.get(axis["name"], {}))
    return RigConfig.model_validate(data)


@pytest.fixture(scope="module")
def fitted(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("two-axis")
    procedure = folder / "imu.yaml"
    procedure.write_text(yaml.safe_dump(TWO_AXIS, sort_keys=False))
    campaign = folder / "imu.h5"
    run_campaign(prepare(procedure), campaign, dry_run=True, seed=5, overwrite=False)
    _, report = fit_and_save(load_campaign(campaign), campaign, folder / "cal.yaml", FitOptions(degree=1))
    return campaign, report


def test_each_fixture_axis_turns_on_the_axis_that_can_turn_it(tmp_path: Path) -> None:
    (tmp_path / "imu.yaml").write_text(yaml.safe_dump(TWO_AXIS, sort_keys=False))
    plan = prepare(tmp_path / "imu.yaml").plan
    kinematics = TurntableKinematics(_rig().turntable.axes)
    turning = [s for stage in plan.stages for s in stage.body if isinstance(s, RateStep)]
    assert {(s.about, s.rate_axis) for s in turning} == {("x", 0), ("y", 0), ("z", 1)}
    for step in turning:   # at the step's pose, turning its axis turns the fixture about the step's fixture axis
        turn = kinematics.turn_in_fixture(step.rate_axis, np.array(step.pose.angles_deg)) * step.table_sign
        np.testing.assert_allclose(turn, np.eye(3)["xyz".index(step.about)], atol=1e-8)


def test_a_vertical_outer_axis_leaves_the_inner_axis_direction_to_the_inner_axis() -> None:
    """A two-axis table with a vertical outer axis: the outer turns the fixture about the directions square to
    the inner axis (fixture y and z with the inner along x); x needs the inner axis's own rate mode."""
    vertical = {"roll": {"axis": [0, 0, 1]}, "spin": {"axis": [-1, 0, 0]}}
    found = spins(RateSteps(rates_dps=[10]), _rig(**vertical), (0.0, 0.0))
    assert {about: (s.rate_axis, s.table_sign) for about, s in found.items()} == {"x": (1, -1.0), "y": (0, 1.0),
                                                                                 "z": (0, 1.0)}
    no_inner_rate = {**vertical, "spin": {"axis": [-1, 0, 0], "max_rate_dps": None, "max_acceleration_dps2": None}}
    with pytest.raises(NoRateAxis) as caught:
        spins(RateSteps(rates_dps=[10]), _rig(**no_inner_rate), (0.0, 0.0))
    assert str(caught.value) == ("rates.about x: no turntable axis with a rate mode turns the fixture about its x axis "
                                 "(roll turns it only about directions 90° from spin's [-1.0, 0.0, 0.0])")


def test_a_rate_the_geometry_cannot_turn_is_one_line_naming_the_procedure(tmp_path: Path) -> None:
    data = yaml.safe_load(RIG.read_text())
    data["turntable"]["axes"][1].pop("max_rate_dps")
    data["turntable"]["axes"][1].pop("max_acceleration_dps2")
    (tmp_path / "rig.yaml").write_text(yaml.safe_dump(data))
    (tmp_path / "imu.yaml").write_text(yaml.safe_dump({**TWO_AXIS, "rig": str(tmp_path / "rig.yaml")}))
    with pytest.raises(ConfigError) as caught:
        prepare(tmp_path / "imu.yaml")
    text = str(caught.value)
    assert "rates.about z" in text and "roll turns it only about directions 90° from spin's" in text
    assert "\n" not in text.strip()


def test_gravity_turned_through_a_rate_step_is_averaged_over_it(fitted: tuple[Path, dict]) -> None:
    """About fixture x on the horizontal outer axis gravity turns in the y–z plane: its reference is the mean
    over the record (shorter than 1 g), and the accelerometer's own mean reads the same within its errors."""
    campaign = load_campaign(fitted[0])
    serial = campaign.serials[0]
    keys = [p.step_key for p in campaign.poses]
    reference = campaign.channel_column(serial, "accel", "reference")
    measured = campaign.channel_column(serial, "accel", "mean")
    fast = [keys.index(k) for k in keys if k.endswith("/rate_xp1000") or k.endswith("/rate_yp500")]
    assert len(fast) == 4
    for row in fast:
        assert np.linalg.norm(reference[row]) < 0.5
        assert np.linalg.norm(measured[row] - reference[row]) < 0.05   # the raw part's bias and scale: tens of mg


def test_the_fit_recovers_the_hidden_gyroscope_as_on_a_three_axis_table(fitted: tuple[Path, dict]) -> None:
    campaign_path, report = fitted
    z = np.array([t["z"] for r in report.values() for t in r["channels"]["gyro"]["truth_error"]])
    assert len(z) == 4 * 2 * 27                          # 4 DUTs, 2 setpoints, 27 parameters
    assert np.max(np.abs(z)) < 4.5 and 0.6 < np.std(z) < 1.5
    campaign = load_campaign(campaign_path)
    for serial in campaign.serials:
        gyro = report[serial]["channels"]["gyro"]
        verification = gyro["verification"]
        assert verification["rate_steps"] == 12                # ±30 and ±700 °/s about x, y, z at 20 °C
        assert verification["rmse_dps"] < verification["rmse_before_dps"] / 50, serial
        records = gyro_records(campaign, serial)
        assert set(np.flatnonzero(np.abs(records.reference_dps[records.rows("rate")]).max(axis=0) > 900)) == {0, 1, 2}
