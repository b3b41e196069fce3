"""`rig fit-recording` refuses what its own checks call implausible, in one line, writing and registering nothing:
a time base no MEMS part samples at (a sample-index column read as seconds), and a fit whose static intervals
scatter far beyond their standard errors. The same recordings read right are fitted and registered."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.handheld.calibrate import MAX_CHI2_REDUCED
from accelcal_rig.handheld.time_base import plausible_rates_hz
from accelcal_rig.parts.registry import part
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from accelcal_rig.sim.handheld import handheld_recording, write_csv

RATE_HZ = 100.0


def _fit(tmp_path: Path, recording: Path, *options: str) -> tuple[int, Path, str]:
    """Exit code, the calibration file asked for, the registry used."""
    output, registry = tmp_path / "cal.yaml", str(tmp_path / "lab.sqlite")
    code = main(["fit-recording", str(recording), "-o", str(output), "--registry", registry, *options])
    return code, output, registry


def _registered(registry: str) -> int:
    return Registry.open(normalised(registry)).count() if Path(registry).exists() else 0


def _sample_index_recording(path: Path) -> Path:
    """A simulated session whose time column counts samples (a logger's index), as many loggers write it."""
    simulated = handheld_recording("HH-7", 14, RATE_HZ, np.random.default_rng(21))
    write_csv(replace(simulated, t_s=np.rint(simulated.t_s * RATE_HZ)), path)
    return path


def test_a_sample_index_read_as_seconds_is_refused_naming_the_file_and_column(tmp_path: Path, capsys) -> None:
    recording = _sample_index_recording(tmp_path / "session.csv")
    code, output, registry = _fit(tmp_path, recording, "--columns", "time_s,ax,ay,az,temp_c", "--part", "adxl355")
    err = capsys.readouterr().err.strip()
    low, _, _ = plausible_rates_hz("adxl355")
    assert code == 2 and len(err.splitlines()) == 1, err
    assert err.startswith(f"rig: error: {recording}: column time_s: ") and "at 1 Hz read as seconds" in err
    assert f"slower than the ADXL355's data rates allow ({low:.4g} …" in err and "--time-unit samples" in err
    assert not output.exists() and _registered(registry) == 0
    # Read as what it is, the same file is fitted and registered.
    code, output, registry = _fit(tmp_path, recording, "--columns", "time_s,ax,ay,az,temp_c", "--time-unit",
                                  "samples", "--rate-hz", str(RATE_HZ), "--part", "adxl355")
    assert code == 0 and output.is_file() and _registered(registry) == 1


def test_the_plausible_rates_are_the_parts_own_with_a_margin() -> None:
    rates = part("adxl355").output_data_rates_hz
    low, high, whose = plausible_rates_hz("adxl355")
    assert low < min(rates) < max(rates) < high and "ADXL355" in whose
    any_low, any_high, _ = plausible_rates_hz("a-part-no-one-knows")
    assert any_low <= low and any_high >= high  # an unknown part: any known part's rates


def test_a_fit_whose_intervals_scatter_far_beyond_their_noise_is_not_written_nor_registered(tmp_path: Path,
                                                                                             capsys) -> None:
    """Each still stretch of a simulated session scaled by its own 0.5 % (as if the sensor had not been still, or
    the intervals spanned motion): the intervals disagree with any one calibration far beyond their noise."""
    simulated = handheld_recording("HH-7", 18, RATE_HZ, np.random.default_rng(22))
    starts = np.flatnonzero(np.diff(np.r_[0, simulated.still.astype(int)]) == 1)
    stretch = np.cumsum(np.isin(np.arange(len(simulated.t_s)), starts))
    gain = 1.0 + 0.005 * np.random.default_rng(23).standard_normal(stretch.max() + 1)
    write_csv(replace(simulated, raw_g=simulated.raw_g * gain[stretch][:, None]), tmp_path / "scattered.csv")
    write_csv(simulated, tmp_path / "still.csv")
    code, output, registry = _fit(tmp_path, tmp_path / "scattered.csv", "--columns", "time_s,ax,ay,az,temp_c")
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "implausible fit" in err, err
    chi2 = float(err.split("χ²_red ")[1].split(",")[0])
    assert chi2 > MAX_CHI2_REDUCED and not output.exists() and _registered(registry) == 0
    code, output, registry = _fit(tmp_path, tmp_path / "still.csv", "--columns", "time_s,ax,ay,az,temp_c", "--json")
    assert code == 0 and output.is_file() and _registered(registry) == 1


@pytest.mark.parametrize("unit, pace, hint", [("ms", "faster", "a column in seconds needs --time-unit s"),
                                               ("samples", "slower", "check --rate-hz")])
def test_the_refusal_says_what_to_check_for_the_unit_given(tmp_path: Path, capsys, unit: str, pace: str,
                                                           hint: str) -> None:
    """Seconds read as milliseconds (a thousand times the rate); a sample index at a --rate-hz no part has."""
    if unit == "ms":
        write_csv(handheld_recording("HH-7", 14, RATE_HZ, np.random.default_rng(24)), tmp_path / "session.csv")
        recording, options = tmp_path / "session.csv", ["--time-unit", "ms"]
    else:
        recording, options = _sample_index_recording(tmp_path / "session.csv"), ["--time-unit", unit, "--rate-hz", "0.5"]
    code, output, _ = _fit(tmp_path, recording, "--columns", "time_s,ax,ay,az,temp_c", *options)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and f"{pace} than any known accelerometer's data rates" in err
    assert hint in err.split("; ")[-1] and not output.exists()
