"""The progress snapshots a campaign hands its listener: phases in order, poses counting up, time left
counting down to nothing, and a listener that fails cannot stop the campaign."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.progress import Progress
from tests.conftest import TINY_PROCEDURE


def test_snapshots_follow_the_campaign(write, workdir: Path) -> None:
    seen: list[Progress] = []
    result = run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), workdir / "run.h5", dry_run=True, seed=0,
                          overwrite=False, progress=seen.append)
    phases = list(dict.fromkeys(p.phase for p in seen))
    assert phases == ["preflight", "ramp", "soak", "poses", "safe", "done"]
    assert [p.poses_done for p in seen] == sorted(p.poses_done for p in seen)
    assert seen[-1].poses_done == 6 and seen[-1].poses_total == 6
    measuring = [p for p in seen if p.remaining_s is not None]
    assert measuring[0].remaining_s > 1200  # a 7 °C ramp and a soak of at least five minutes lie ahead
    assert measuring[-1].remaining_s < 60  # the last pose's time
    # Time left plus time spent stays near the estimate's total: the estimate tracks the run.
    totals = [p.remaining_s + p.clock_s for p in measuring]
    assert max(totals) - min(totals) < 0.15 * result.summary.virtual_duration_s
    soak = [p for p in seen if p.phase == "soak"]
    assert soak and all(p.setpoint_c == 30.0 and p.setpoint_number == 1 for p in soak)
    assert soak[-1].chamber_c is not None and len(soak[-1].dut_c) == 4
    assert "T30 (1/1) soak" in soak[-1].line() and "pose 0/6" in soak[-1].line() and "left" in soak[-1].line()
    assert seen[-1].setpoint_c is None and "left" not in seen[-1].line()


def test_a_failing_listener_is_reported_once_and_the_campaign_completes(write, workdir: Path, caplog) -> None:
    calls = []

    def broken(progress: Progress) -> None:
        calls.append(progress)
        raise RuntimeError("display gone")

    result = run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), workdir / "run.h5", dry_run=True, seed=0,
                          overwrite=False, progress=broken)
    assert result.summary.state == "done" and result.summary.poses_done == 6
    assert len(calls) == 1
    assert sum("progress display failed" in r.getMessage() for r in caplog.records) == 1
