"""`rig status` as a person reads it: no Python values, what the campaign does now, and what to do next."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

from accelcal_rig.cli import main
from accelcal_rig.cli.status_text import status_lines
from tests.conftest import REPO

RIG = str(Path(sys.executable).parent / "rig")


def status(**changes: object) -> dict:
    base = {"file": "c.h5", "procedure": "quick-6pos", "state": "done", "writer": None, "runs": 1, "poses_done": 12,
            "poses_total": 12, "next_step": None, "samples_per_pose": 200, "duts": ["A-1", "A-2"],
            "setpoints_c": [15.0, 35.0], "dry_run": True, "started": "2026-12-01T16:46:29+00:00",
            "finished": "2026-12-01T16:46:30+00:00", "abort_reason": None, "last_event": "fit → done",
            "integrity": "ok", "campaign_file": "current", "progress": None}
    return base | changes


def test_a_finished_campaign_reads_without_python_values() -> None:
    text = "\n".join(status_lines(status()))
    assert "None" not in text and "[" not in text and "True" not in text
    assert "setpoints  2: 15, 35 °C" in text and "started    2026-12-01 16:46:29 UTC" in text
    assert "next" not in text


def test_a_running_campaign_says_what_it_does_now() -> None:
    line = "T35 (2/2) soak 0:10:00 · chamber 35.0 °C · DUT 34.90…34.95 °C · pose 6/12 · 0:25:00 left"
    text = status_lines(status(state="running", writer="alive (pid 7)", poses_done=6, next_step="T35/pose01",
                               finished=None, progress={"line": line, "remaining_s": 1500.0}))
    assert "state      running, writer alive (pid 7)" in text
    assert f"now        {line}" in text and "poses      6 of 12, next T35/pose01" in text


def test_a_stopped_campaign_says_how_to_continue() -> None:
    aborted = status_lines(status(state="aborted", abort_reason="chamber alarm", poses_done=3))
    assert aborted[-1] == "next       rig resume c.h5  (continues with the poses not stored)"
    died = status_lines(status(state="running", writer="gone (pid 7 on lab ended without closing it)", finished=None))
    assert died[-1].startswith("next       rig resume c.h5")


def test_watch_follows_a_running_campaign_to_its_end(tmp_path: Path) -> None:
    campaign = tmp_path / "live.h5"
    run = subprocess.Popen([RIG, "run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(campaign),
                            "-q", "--no-pdf", "--faults", "rate=1,kinds=delay,delay_s=0.005"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not campaign.with_name("live.h5.journal").exists():
            assert run.poll() is None and time.monotonic() < deadline, "the campaign never started"
            time.sleep(0.05)
        watched = subprocess.run([RIG, "status", str(campaign), "--watch", "0.5", "--json"], capture_output=True,
                                 text=True, timeout=300)
    finally:
        run.wait(timeout=300)
    snapshots = [json.loads(line) for line in watched.stdout.splitlines()]
    assert watched.returncode == 0 and len(snapshots) >= 3
    assert snapshots[-1]["state"] == "done" and any(s["state"] == "running" and s["progress"] for s in snapshots)
    done = [s["poses_done"] for s in snapshots]
    assert done == sorted(done) and done[-1] == 12


def test_status_of_a_finished_file_prints_once(capsys) -> None:
    assert main(["status", str(REPO / "tests" / "data" / "real" / "README.md"), "--watch"]) == 2  # not a campaign
    assert capsys.readouterr().err.startswith("rig: error:")
