"""The positions study on a dry run with known truth: every size scored on held-out poses, the scores
falling towards the noise floor as positions are added, the structured subsets evenly spread."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.analysis.positions import structured_subset
from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli import main
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.schedules import sphere
from tests.conftest import TINY_PROCEDURE
from tests.report.test_html_report import png_size

STUDY = TINY_PROCEDURE.replace("schedule: {kind: six-position}", "schedule: {kind: sphere, count: 96}").replace(
    "samples_per_pose: 20", "samples_per_pose: 100")


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> Path:
    import shutil

    from tests.conftest import SIM_RIG

    folder = tmp_path_factory.mktemp("positions")
    shutil.copy(SIM_RIG, folder / "sim.yaml")
    (folder / "study.yaml").write_text(STUDY)
    output = folder / "study.h5"
    run_campaign(prepare(folder / "study.yaml"), output, dry_run=True, seed=0, overwrite=False)
    return output


def test_scores_fall_towards_the_noise_floor(study: Path, tmp_path: Path, capsys) -> None:
    figure = tmp_path / "positions.png"
    assert main(["analyze", "positions", str(study), "--sizes", "96,48,24,12", "--subsets", "6", "--json",
                 "--figure", str(figure)]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["mode"] == "reference" and result["setpoint_c"] == 30.0
    rows = result["sizes"]
    assert {r["serial"] for r in rows} == {"ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"}
    for serial, floor in result["noise_floor_mg"].items():
        mine = {r["size"]: r for r in rows if r["serial"] == serial}
        assert sorted(mine) == [12, 24, 48, 96]
        assert mine[96]["held_out"] == 0 and mine[48]["held_out"] == 48 and mine[12]["held_out"] == 84
        assert mine[96]["structured_mg"] < 1.3 * floor  # all poses: at the floor
        assert mine[24]["random_median_mg"] < 1.5 * floor
        assert mine[12]["random_max_mg"] > mine[48]["random_median_mg"]  # fewer positions, worse worst case
        assert all(r["before_mg"] > 100 * floor for r in mine.values())
        assert all(r["failed"] == 0 for r in mine.values())
    width, height = png_size(figure)
    assert width > 600 and height > 400


def test_the_table_names_each_size(study: Path, capsys) -> None:
    assert main(["analyze", "positions", str(study), "--sizes", "96,12", "--subsets", "2"]) == 0
    out = capsys.readouterr().out
    assert "reference fits at 30 °C" in out
    assert sum(line.split()[1] == "12" for line in out.splitlines()[2:-1]) == 4


def test_structured_subsets_are_evenly_spread() -> None:
    directions = sphere(1296)
    chosen = structured_subset(directions, 24)
    assert len(set(chosen.tolist())) == 24
    np.testing.assert_allclose(directions[chosen].mean(axis=0), 0.0, atol=0.05)  # balanced over the sphere


def test_a_campaign_of_several_setpoints_asks_which(paper_campaign: Path, capsys) -> None:
    assert main(["analyze", "positions", str(paper_campaign)]) == 2
    assert "choose one with --setpoint" in capsys.readouterr().err
