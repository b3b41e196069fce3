"""The free cool-down: a procedure that heats, holds a pose, switches the chamber off and records while
the simulated sensors cool; the analysis finds their temperature coefficients and the calibration
removes them."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli import main
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from tests.conftest import REPO
from tests.report.test_html_report import png_size

SHORT = (REPO / "procedures" / "cooldown-60c.yaml").read_text().replace("duration_min: 240", "duration_min: 90") \
    .replace("record_every_s: 60", "record_every_s: 120").replace("rig: ../configs/sim.yaml", "rig: sim.yaml")


@pytest.fixture(scope="module")
def cooldown(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    import shutil

    from tests.conftest import SIM_RIG

    folder = tmp_path_factory.mktemp("cooldown")
    shutil.copy(SIM_RIG, folder / "sim.yaml")
    (folder / "cool.yaml").write_text(SHORT)
    output = folder / "cool.h5"
    result = run_campaign(prepare(folder / "cool.yaml"), output, dry_run=True, seed=1, overwrite=False)
    return output, result


def test_the_campaign_records_on_schedule_while_the_chamber_is_off(cooldown) -> None:
    output, result = cooldown
    assert result.summary.state == "done" and result.summary.poses_done == 46  # one at the start, 45 × 2 min
    with h5py.File(output, "r") as f:
        keys = [k.decode() for k in f["poses/step_key"][:]]
        assert keys[0] == "T60/cool0001" and keys[-1] == "T60/cool0046"
        assert set(f["poses/pose_number"][:].tolist()) == {5}  # one pose held throughout
        t = f["poses/t_start_s"][:]
        np.testing.assert_allclose(np.diff(t)[1:], 120.0, atol=0.6)  # the position poll's half second
        assert 120.0 <= t[1] - t[0] <= 130.0  # the first interval also holds the first record itself
        temperature = f["duts/ADX355-A001/temperature_c"][:].mean(axis=1)
        assert temperature[0] > 59.0 and temperature[-1] < 40.0 and np.all(np.diff(temperature) < 0.3)
        messages = [m.decode() for m in f["events/message"][:]]
    assert any("chamber switched off" in m for m in messages)
    assert not any("left the" in m for m in messages)  # cooling is the point, not a band violation


def test_analysis_finds_the_coefficients_and_the_calibration_removes_them(cooldown, fitted_paper_campaign,
                                                                         tmp_path: Path, capsys) -> None:
    output, _ = cooldown
    figure = tmp_path / "cool.png"
    assert main(["analyze", "cooldown", str(output), "--calibration", str(fitted_paper_campaign[1]), "--json",
                 "--figure", str(figure)]) == 0
    sensors = json.loads(capsys.readouterr().out)["sensors"]
    assert len(sensors) == 4
    for s in sensors:
        before = np.abs(s["coefficient_before_ug_per_k"])
        after = np.abs(s["coefficient_after_ug_per_k"])
        assert before.max() > 50.0  # the simulated sensors drift 10–20 mg over 100 K
        assert np.all(after < 0.05 * before.max())
        assert s["records"] == 46
    png_size(figure)


def test_a_cooldown_needs_one_setpoint_and_a_pose_the_schedule_has(write, capsys) -> None:
    path = write("cool.yaml", SHORT.replace("setpoints_c: [60]", "setpoints_c: [50, 60]"))
    with pytest.raises(ConfigError, match="a cool-down procedure has one setpoint"):
        prepare(path)
    path = write("cool.yaml", SHORT.replace("pose: 5 ", "pose: 9 "))
    with pytest.raises(ConfigError, match=r"cool\.yaml:\d+: cooldown\.pose: pose 9 asked for, the schedule has 6"):
        prepare(path)


def test_the_estimate_counts_the_records(write) -> None:
    from accelcal_rig.engine.estimate import estimate_duration

    prepared = prepare(write("cool.yaml", SHORT))
    row = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan).setpoints[0]
    assert row.poses_s == pytest.approx(90 * 60, abs=60)
