"""The tilt check: Table 5's poses measured on the simulated rig, angles before and after the paper
campaign's calibration against the reference the turntable set."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.analysis.tilt import pitch_roll_deg
from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli import main
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.schedules import tilt
from tests.conftest import REPO


def test_schedule_and_eq10_are_inverse() -> None:
    angles = np.array([[0, 0], [15, 0], [30, 0], [0, -15], [0, -30], [15, -15], [30, -30], [-40, 120]], dtype=float)
    np.testing.assert_allclose(pitch_roll_deg(tilt(angles)), angles, atol=1e-12)
    np.testing.assert_allclose(tilt(np.array([[0.0, 0.0]])), [[0, 0, 1]], atol=1e-15)  # level: z up reads +1 g


@pytest.fixture(scope="module")
def tilt_campaign(tmp_path_factory: pytest.TempPathFactory) -> Path:
    output = tmp_path_factory.mktemp("tilt") / "tilt.h5"
    run_campaign(prepare(REPO / "procedures" / "tilt-check.yaml"), output, dry_run=True, seed=5, overwrite=False,
                 calibration=output.with_suffix(".calibration.yaml"))
    assert not output.with_suffix(".calibration.yaml").exists()  # fit.mode none: measured only
    return output


def test_calibration_brings_every_angle_to_its_reference(tilt_campaign: Path, fitted_paper_campaign, capsys) -> None:
    calibration = fitted_paper_campaign[1]
    assert main(["analyze", "tilt", str(tilt_campaign), "--calibration", str(calibration), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    rows = result["rows"]
    assert len(rows) == 7 * 4 and result["setpoint_c"] == 25.0 and result["outside_range"] == []
    first = [r for r in rows if r["serial"] == "ADX355-A001"]
    np.testing.assert_allclose([r["reference_deg"] for r in first],
                               [[0, 0], [15, 0], [30, 0], [0, -15], [0, -30], [15, -15], [30, -30]], atol=0.01)
    for r in rows:
        after = np.abs(np.subtract(r["after_deg"], r["reference_deg"]))
        assert after.max() < 0.01  # degrees: the table's 3″ and the noise
        np.testing.assert_allclose(r["seoq_percent"], np.abs(np.subtract(r["before_deg"], r["after_deg"])) / 30 * 100)
    assert max(np.abs(np.subtract(r["before_deg"], r["reference_deg"])).max() for r in rows) > 0.5


def test_the_table_and_a_foreign_calibration(tilt_campaign: Path, fitted_paper_campaign, tmp_path: Path,
                                             capsys) -> None:
    calibration = fitted_paper_campaign[1]
    assert main(["analyze", "tilt", str(tilt_campaign), "--calibration", str(calibration)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"ADX355-A004 +worst \|error\|: [\d.]+° without, 0\.00\d\d° after", out) and "SEOQ (%)" in out
    foreign = tmp_path / "other.yaml"
    foreign.write_text(calibration.read_text().replace("ADX355-A003", "ADX355-Z999"))
    assert main(["analyze", "tilt", str(tilt_campaign), "--calibration", str(foreign)]) == 2
    assert "no accelerometer calibration for ADX355-A003" in capsys.readouterr().err


def test_rig_fit_asks_for_a_mode_on_a_measure_only_campaign(tilt_campaign: Path, tmp_path: Path, capsys) -> None:
    assert main(["fit", str(tilt_campaign), "-o", str(tmp_path / "c.yaml")]) == 2
    assert "asked for no fit (fit.mode: none)" in capsys.readouterr().err
