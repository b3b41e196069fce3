"""`rig characterise`: on a dry run it recovers the simulator's thermal constants, its written constants are
what `rig plan` then uses, and the estimate made with them is checked against the next campaign."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from accelcal_rig.config.load import load_rig
from tests.conftest import REPO, SIM_RIG

RIG = str(Path(sys.executable).parent / "rig")


def rig(*argv: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([RIG, *argv], capture_output=True, text=True, timeout=600, cwd=cwd)


def test_a_dry_run_gives_back_the_simulators_constants(paper_campaign: Path) -> None:
    result = rig("characterise", str(paper_campaign), "--json")
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout)
    thermal, sim = found["thermal"], load_rig(SIM_RIG).model
    commanded = sim.chamber.ramp_rate_c_per_min
    assert thermal["heating_rate_c_per_min"] == pytest.approx(commanded, rel=0.02)
    assert thermal["cooling_rate_c_per_min"] == pytest.approx(commanded, rel=0.02)
    assert thermal["cooling_floor_c"] is None                       # the simulated chamber has none
    assert thermal["chamber_time_constant_min"] == pytest.approx(sim.simulation.chamber_time_constant_min, rel=0.05)
    assert thermal["chamber_overshoot_pct"] < 0.5                   # nor any overshoot
    slowest_min = max(sim.simulation.fixture_time_constants_s([s.serial for s in sim.fixture.sensors])) / 60.0
    assert thermal["fixture_time_constant_min"] == pytest.approx(slowest_min, rel=0.03)
    assert found["air_residual_rms_c"] < 2 * sim.simulation.chamber_noise_c
    assert found["estimated_now_s"] == pytest.approx(found["took_s"], rel=0.02)


def test_written_constants_are_the_next_estimate_and_it_is_checked_against_the_next_campaign(
        paper_campaign: Path, tmp_path: Path) -> None:
    config = tmp_path / "lab.yaml"
    original = SIM_RIG.read_text().split("\n# The rig's own thermal constants")[0]  # a rig never characterised
    config.write_text(original)
    defaults = rig("plan", str(REPO / "procedures" / "quick-6pos.yaml"), "--config", str(config))
    assert "thermal    heating 3 °C/min" in defaults.stdout and "defaults for heating_rate_c_per_min" in defaults.stdout
    written = rig("characterise", str(paper_campaign), "--write", str(config))
    assert written.returncode == 0, written.stderr
    assert config.read_text().startswith(original)                  # every line of the lab's file kept
    assert "\nthermal:\n  heating_rate_c_per_min: " in config.read_text()[len(original):]
    plan = rig("plan", str(REPO / "procedures" / "quick-6pos.yaml"), "--config", str(config))
    assert f"thermal    the rig's own (rig characterise {paper_campaign.name} on " in plan.stdout
    # the next campaign, on the rig those constants describe: its own estimate against what it took
    next_campaign = tmp_path / "next.h5"
    run = rig("run", str(REPO / "procedures" / "quick-6pos.yaml"), "--config", str(config), "--dry-run", "-o",
              str(next_campaign), "-q", "--no-pdf", "--registry", str(tmp_path / "registry.sqlite"))
    assert run.returncode == 0, run.stderr
    checked = json.loads(rig("characterise", str(next_campaign), "--json").stdout)
    assert checked["estimated_then_s"] == pytest.approx(checked["took_s"], rel=0.03)


def test_a_campaign_file_that_is_not_one_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "c.h5").write_bytes(b"not a campaign")
    result = rig("characterise", str(tmp_path / "c.h5"))
    assert result.returncode == 2 and len(result.stderr.strip().splitlines()) == 1
    assert result.stderr.startswith(f"rig: error: {tmp_path / 'c.h5'}")
