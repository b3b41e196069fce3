"""The real imucal session (tests/data/real): the detector finds its six static poses without reading the
labels, the six-parameter fit agrees with imucal's published calibration, and nine parameters are refused."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.handheld.calibrate import RecordingUnusable, fit_recording
from accelcal_rig.handheld.recording import CsvLayout, read_csv_recording
from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals
from tests.conftest import REPO

DATA = REPO / "tests" / "data" / "real"
SESSION = DATA / "imucal-annotated-session.csv"
RATE_HZ = 204.8
LAYOUT = CsvLayout.parse_columns("samples,acc_x,acc_y,acc_z", time_unit="samples", rate_hz=RATE_HZ, units="counts",
                                 counts_per_g=2048.0)


@pytest.fixture(scope="module")
def found():
    recording = read_csv_recording(SESSION, LAYOUT)
    return recording, detect_static_intervals(recording.t_s, recording.accel_g, None, DetectorSettings(), "session")


def test_the_six_static_poses_are_found_without_the_labels(found) -> None:
    _, detection = found
    with open(SESSION, newline="") as handle:
        label_of = {int(r["samples"]): r["part"] for r in csv.DictReader(handle)}
    labels = []
    for interval in detection.intervals:
        samples = range(round(interval.start_s * RATE_HZ), round(interval.end_s * RATE_HZ) + 1)
        parts = {label_of[s] for s in samples}
        assert len(parts) == 1, parts  # each interval inside one labelled pose
        labels.append(parts.pop())
    assert sorted(labels) == ["x_a", "x_p", "y_a", "y_p", "z_a", "z_p"]  # each pose once; no rotation


def test_six_parameter_fit_agrees_with_imucal(found) -> None:
    recording, detection = found
    result = fit_recording(recording, detection, "bias-scale", "imucal")
    reference = json.loads((DATA / "imucal-reference-calibration.json").read_text())
    bias_counts = result.fit.parameters[0:3] * 2048.0
    counts_per_g = 2048.0 / result.fit.parameters[3:6]
    np.testing.assert_allclose(bias_counts, reference["b_a"], atol=0.6)  # counts: 0.3 mg
    np.testing.assert_allclose(counts_per_g / (np.diag(reference["K_a"]) * 9.81), 1.0, atol=3e-4)
    assert any("no check left" in w for w in result.report["warnings"])  # six poses, six parameters


def test_nine_parameters_from_six_poses_are_refused(found, tmp_path: Path, capsys) -> None:
    recording, detection = found
    with pytest.raises(RecordingUnusable, match="6 static intervals found, a 9-parameter"):
        fit_recording(recording, detection, "all", "imucal")
    argv = ["fit-recording", str(SESSION), "--columns", "samples,acc_x,acc_y,acc_z", "--time-unit", "samples",
            "--rate-hz", "204.8", "--units", "counts", "--counts-per-g", "2048", "-o", str(tmp_path / "cal.yaml")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--parameters bias-scale" in err
    assert not (tmp_path / "cal.yaml").exists()
    assert main([*argv, "--parameters", "bias-scale", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert len(report["intervals"]) == 6 and (tmp_path / "cal.yaml").exists()
