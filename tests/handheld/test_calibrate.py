"""Hand-held calibration: the truth of a simulated sensor recovered from a synthetic recording written as
a real logger would (16-bit offset binary at 100 Hz, 20-bit ADXL355 codes, g), and clear refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import apply, load_calibration, save_calibration
from accelcal_rig.fit.sfem import norm_only_gauge
from accelcal_rig.handheld.calibrate import RecordingUnusable, fit_recording
from accelcal_rig.handheld.recording import CsvLayout, read_campaign_recording, read_csv_recording
from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals
from accelcal_rig.sim.handheld import handheld_recording, write_csv

ENCODINGS = {
    "16-bit offset binary": ({"counts_per_g": 16384, "zero_code": 32768, "bits": 16},
                             {"units": "counts", "counts_per_g": 16384, "zero_code": 32768}),
    "20-bit ADXL355 codes": ({"counts_per_g": 256000, "bits": 20}, {"units": "counts", "counts_per_g": 256000}),
    "g": ({}, {"units": "g"}),
}


def calibrate_csv(path: Path, layout: CsvLayout, free: str = "all"):
    recording = read_csv_recording(path, layout)
    detection = detect_static_intervals(recording.t_s, recording.accel_g, recording.temperature_c, DetectorSettings(),
                                        recording.source)
    return recording, fit_recording(recording, detection, free, "HH-7")


@pytest.mark.parametrize("encoding", list(ENCODINGS))
def test_truth_recovered_from_a_synthetic_recording(tmp_path: Path, encoding: str) -> None:
    written, read = ENCODINGS[encoding]
    simulated = handheld_recording("HH-7", 18, 100.0, np.random.default_rng(11))
    path = tmp_path / "session.csv"
    write_csv(simulated, path, **written)
    if "zero_code" in written:
        codes = np.loadtxt(path, delimiter=",", skiprows=1)[:, 1:4]
        assert 16000 < np.median(np.abs(codes)) and codes.max() < 65536 and codes.min() >= 0  # around 32768
    _, result = calibrate_csv(path, CsvLayout.parse_columns("time_s,ax,ay,az,temp_c", **read))
    fit = result.fit
    truth = norm_only_gauge(simulated.truth_parameters)
    z = (fit.parameters - truth)[fit.free] / fit.sigma[fit.free]
    assert np.all(np.abs(z) < 4.0), z
    assert np.max(np.abs(fit.parameters[:3] - truth[:3])) < 50e-6  # bias within 50 µg
    assert result.report["n_intervals"] == 18
    assert result.report["rmse_after_mg"] < 1.5 * result.report["noise_floor_mg"]
    assert result.report["temperature_c"] == pytest.approx(25.0, abs=0.01)


def test_the_calibration_file_applies_like_a_campaigns(tmp_path: Path) -> None:
    simulated = handheld_recording("HH-7", 18, 100.0, np.random.default_rng(12))
    write_csv(simulated, tmp_path / "s.csv")
    _, result = calibrate_csv(tmp_path / "s.csv", CsvLayout.parse_columns("time_s,ax,ay,az,temp_c"))
    save_calibration(result.calibration, tmp_path / "cal.yaml")
    sensor = load_calibration(tmp_path / "cal.yaml").channel("HH-7", "accel")
    still = simulated.raw_g[simulated.still]
    compensated = apply(sensor, still, 25.0)
    assert np.sqrt(np.mean((np.linalg.norm(compensated, axis=1) - 1.0) ** 2)) < 0.3e-3  # per-sample noise ~0.2 mg
    assert np.sqrt(np.mean((np.linalg.norm(still, axis=1) - 1.0) ** 2)) > 5e-3


def test_too_few_orientations_name_what_is_missing(tmp_path: Path) -> None:
    simulated = handheld_recording("HH-7", 7, 100.0, np.random.default_rng(13))
    write_csv(simulated, tmp_path / "s.csv")
    with pytest.raises(RecordingUnusable, match="7 static intervals found, a 9-parameter norm-only fit needs at "
                                                "least 9 .* --parameters bias-scale"):
        calibrate_csv(tmp_path / "s.csv", CsvLayout.parse_columns("time_s,ax,ay,az,temp_c"))


def test_poorly_spread_orientations_name_the_missing_directions(tmp_path: Path) -> None:
    simulated = handheld_recording("HH-7", 14, 100.0, np.random.default_rng(14))
    upright = simulated.raw_g.copy()
    upright[:, 2] = np.abs(upright[:, 2])  # as if z never pointed down
    np.savetxt(tmp_path / "s.csv", np.column_stack([simulated.t_s, upright]), delimiter=",", header="t,x,y,z",
               comments="")
    with pytest.raises(RecordingUnusable, match="but none with z down"):
        calibrate_csv(tmp_path / "s.csv", CsvLayout.parse_columns("t,x,y,z"))


def test_a_campaign_files_raw_samples_are_a_recording(paper_campaign: Path) -> None:
    recording = read_campaign_recording(paper_campaign, "ADX355-A002", 20.0)
    detection = detect_static_intervals(recording.t_s, recording.accel_g, recording.temperature_c, DetectorSettings(),
                                        recording.source)
    # One per pose, the 24 calibration poses and the 12 verification poses: the moves are gaps in time.
    assert len(detection.intervals) == 24 + 12
    result = fit_recording(recording, detection, "all", "ADX355-A002")
    assert result.report["rmse_after_mg"] < 1.5 * result.report["noise_floor_mg"]
    assert result.report["temperature_c"] == pytest.approx(20.0, abs=0.5)


@pytest.mark.parametrize("argv, expected", [
    (["--columns", "time_s,ax,ay,accel_z"], "no column accel_z (columns: time_s, ax, ay, az, temp_c)"),
    (["--columns", "1,2,3,9"], "column 9 asked for, its first line has 5"),
    (["--columns", "t,x"], "--columns: 't,x': expected time,x,y,z"),
    (["--columns", "time_s,ax,ay,az", "--window-s", "0"], "--window-s: 0 is outside 0.001 … 3600 s"),
    (["--columns", "time_s,ax,ay,az", "--init-s", "nan"], "--init-s: nan is outside 0.001 … 3600 s"),
])
def test_fit_recording_input_errors_are_one_line(tmp_path: Path, capsys, argv: list[str], expected: str) -> None:
    from accelcal_rig.cli import main

    simulated = handheld_recording("HH-7", 10, 100.0, np.random.default_rng(15))
    write_csv(simulated, tmp_path / "s.csv")
    try:
        code = main(["fit-recording", str(tmp_path / "s.csv"), "-o", str(tmp_path / "cal.yaml"), *argv])
    except SystemExit as exit_:  # command-line mistakes are argparse's to refuse
        code = exit_.code
    assert code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and expected in err, err
    assert not (tmp_path / "cal.yaml").exists()


def test_a_broken_row_is_named_by_its_line(tmp_path: Path) -> None:
    path = tmp_path / "s.csv"
    path.write_text("t,x,y,z\n" + "".join(f"{i / 100},0,0,1\n" for i in range(20)) + "0.2,0,zero,1\n")
    with pytest.raises(ConfigError, match=r"s\.csv:22: not a number in columns t, x, y, z \(delimited by ','\)"):
        read_csv_recording(path, CsvLayout.parse_columns("t,x,y,z"))


@pytest.mark.parametrize("layout", ["whitespace, no header", "tabs, header, by number", "semicolons, header"])
def test_delimiters_headers_and_column_numbers(tmp_path: Path, layout: str) -> None:
    simulated = handheld_recording("HH-7", 12, 100.0, np.random.default_rng(16))
    write_csv(simulated, tmp_path / "s.csv")
    lines = (tmp_path / "s.csv").read_text().splitlines()
    if layout == "whitespace, no header":
        text, columns = "\n".join("  ".join(line.split(",")) for line in lines[1:]), "1,2,3,4,5"
    elif layout == "tabs, header, by number":
        text, columns = "\n".join("\t".join(line.split(",")) for line in lines), "1,2,3,4,5"
    else:
        text, columns = "\n".join(";".join(line.split(",")) for line in lines), "time_s,ax,ay,az,temp_c"
    (tmp_path / "other.txt").write_text(text + "\n")
    _, result = calibrate_csv(tmp_path / "other.txt", CsvLayout.parse_columns(columns))
    _, reference = calibrate_csv(tmp_path / "s.csv", CsvLayout.parse_columns("time_s,ax,ay,az,temp_c"))
    np.testing.assert_array_equal(result.fit.parameters, reference.fit.parameters)  # the same numbers read


def test_codes_without_counts_per_g_give_the_same_calibrated_output(tmp_path: Path) -> None:
    simulated = handheld_recording("HH-7", 14, 100.0, np.random.default_rng(17))
    write_csv(simulated, tmp_path / "codes.csv", counts_per_g=256000.0)
    columns = "time_s,ax,ay,az,temp_c"
    known, with_scale = calibrate_csv(tmp_path / "codes.csv", CsvLayout.parse_columns(columns, units="counts",
                                                                                       counts_per_g=256000.0))
    guessed, without = calibrate_csv(tmp_path / "codes.csv", CsvLayout.parse_columns(columns, units="counts"))
    assert guessed.lsb_g != known.lsb_g and any("--counts-per-g not given" in n for n in guessed.notes)
    codes = np.rint(simulated.raw_g[simulated.still][:50] * 256000.0)
    a = apply(with_scale.calibration.channel("HH-7", "accel"), codes * known.lsb_g, 25.0)
    b = apply(without.calibration.channel("HH-7", "accel"), codes * guessed.lsb_g, 25.0)
    np.testing.assert_allclose(a, b, atol=2e-6)  # the fitted scale absorbs the provisional one


def test_mixed_or_zero_column_numbers_are_refused() -> None:
    with pytest.raises(ConfigError, match="all names or all numbers"):
        CsvLayout.parse_columns("1,ax,ay,az")
    with pytest.raises(ConfigError, match="count from 1"):
        CsvLayout.parse_columns("0,1,2,3")
