"""What a campaign's page and the list say of it beyond its progress: one pose count (the journal's, which a
late progress snapshot cannot contradict), each DUT's verdict from the calibration its follow-up names (read
again when that file changes), where it was interrupted and resumed, and a styled 404 for a name not watched."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest
from starlette.routing import Route
from starlette.testclient import TestClient

from accelcal_rig.engine.progress import Progress
from accelcal_rig.registry.location import normalised
from accelcal_rig.store.paths import progress_path
from accelcal_rig.web.app import create_app
from accelcal_rig.web.interruptions import DIED, interruptions, resume_markers
from tests.conftest import REPO

QUICK = str(REPO / "procedures" / "quick-6pos.yaml")
VERDICTS = {"PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"}


def _run(code: int, *argv: str) -> None:
    from accelcal_rig.cli import main

    assert main([*argv, "-q", "--no-pdf"]) == code


@pytest.fixture(scope="module")
def resumed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A dry run whose chamber stalls on its way to the second setpoint (aborted after the first's poses),
    resumed to the end, its calibration written away from it (`--calibration`)."""
    folder = tmp_path_factory.mktemp("resumed")
    campaign, registry = folder / "stall.h5", normalised(str(folder / "registry.sqlite"))
    (folder / "fits").mkdir()
    _run(1, "run", QUICK, "--dry-run", "-o", str(campaign), "--faults", "chamber_stall_after_min=40",
         "--registry", registry, "--calibration", str(folder / "fits" / "stall.yaml"))
    _run(0, "resume", str(campaign))
    return folder


def client(folder: Path) -> TestClient:
    return TestClient(base_url="http://127.0.0.1", app=create_app([folder], None))


def test_each_duts_verdict_is_read_from_where_the_follow_up_put_the_calibration(resumed: Path) -> None:
    rows = client(resumed).get("/api/campaigns").json()
    verdicts = rows[0]["verdicts"]
    assert rows[0]["state"] == "done" and sorted(verdicts) == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]
    assert all(v["verdict"] in VERDICTS and isinstance(v["reasons"], list) for v in verdicts.values())
    assert client(resumed).get("/api/campaigns/stall.h5").json()["verdicts"] == verdicts
    page = client(resumed).get("/campaigns/stall.h5").text
    assert 'id="verdicts"' in page and page.count('<tr><td>ADX355-A0') == 4
    assert all(reason in page for v in verdicts.values() for reason in v["reasons"])
    front = client(resumed).get("/").text
    counted = {v["verdict"] for v in verdicts.values()}
    assert all(f"{sum(v['verdict'] == c for v in verdicts.values())} {c}</span>" in front for c in counted)


def test_verdicts_are_read_again_when_the_calibration_changes_and_none_is_no_error(resumed: Path, tmp_path: Path,
                                                                                 monkeypatch) -> None:
    from accelcal_rig.web import campaigns as module

    reads = []
    real = module.calibration_verdicts
    monkeypatch.setattr(module, "calibration_verdicts", lambda *a: reads.append(a) or real(*a))
    folders = module.CampaignFolders([resumed])
    fitted = folders.summary("stall.h5")["verdicts"]
    assert fitted and folders.summary("stall.h5")["verdicts"] == fitted and len(reads) == 1  # cached
    calibration = resumed / "fits" / "stall.yaml"
    shutil.move(calibration, tmp_path / "away.yaml")
    try:
        gone = folders.summary("stall.h5")
        assert gone["verdicts"] == {} and gone["calibration"] is None and gone["state"] == "done" and not gone["error"]
        page = client(resumed).get("/campaigns/stall.h5")
        assert page.status_code == 200 and "none yet (judged when the campaign is fitted)" in page.text
    finally:
        shutil.move(tmp_path / "away.yaml", calibration)
    assert folders.summary("stall.h5")["verdicts"] == fitted and len(reads) == 4  # and once for the page's app


def test_a_resume_is_listed_and_marked_on_the_temperature_plot(resumed: Path) -> None:
    summary = client(resumed).get("/api/campaigns/stall.h5").json()
    (stop,) = summary["interruptions"]
    assert stop["run"] == 2 and "reaching 35 °C: not reached" in stop["why"] and stop["down"] is not None
    assert stop["stopped_clock_s"] == stop["resumed_clock_s"] and stop["gap_s"] == 0  # a dry run's clock waits
    page = client(resumed).get("/campaigns/stall.h5").text
    assert 'id="interruptions"' in page and stop["why"] in page and stop["down"] in page
    plot = page.split("<h2>Temperatures</h2>")[1].split("</svg>")[0]
    assert plot.count('class="marker"') == 1 and ">run 2</text>" in plot and "resumed (run N)" in plot
    assert 'class="gap"' not in plot and "rig down</text>" not in plot


def test_a_real_clock_gap_and_a_run_that_died_are_told_apart() -> None:
    """On a real clock the campaign clock runs on while the rig is down: the gap is shaded before the resume.
    A run that left its file `running` died; one that left it `aborted` says why."""
    def event(t_s: float, wall: str, kind: str, message: str, level: str = "info") -> SimpleNamespace:
        return SimpleNamespace(t_s=t_s, wall_time=f"2026-12-01T{wall}+00:00", kind=kind, message=message, level=level)

    campaign = SimpleNamespace(runs=[SimpleNamespace(run=2, started="2026-12-01T02:00:00+00:00")], events=[
        event(100.0, "01:00:00", "fault", "campaign aborted: chamber stalled", "error"),
        event(3700.0, "02:00:00", "resume", "run 2 resumes after 6 stored poses (the last run left the file 'aborted')"),
        event(3800.0, "02:30:00", "pose", "stored"),
        event(5600.0, "03:00:05", "resume", "run 3 resumes after 9 stored poses (the last run left the file 'running')"),
    ])
    first, second = interruptions(campaign)
    assert (first.why, first.down_s, first.gap_s) == ("chamber stalled", 3600.0, 3600.0)
    assert (second.why, second.down_s, second.gap_s) == (DIED, 1805.0, 1800.0)
    assert second.resumed == "2026-12-01T03:00:05+00:00"  # no RunStart of run 3 kept: the event's own time
    assert first.resumed == "2026-12-01T02:00:00+00:00" and first.as_dict()["down"] == "1:00:00"
    markers = resume_markers([first, second])
    assert [(m.label, m.since) for m in markers] == [("run 2", 100.0 / 3600), ("run 3", 3800.0 / 3600)]


def test_the_now_line_does_not_contradict_the_stored_pose_count(resumed: Path, tmp_path: Path, monkeypatch) -> None:
    """The progress snapshot is written at most every half second: a dry run stores poses between two. The
    page shows the journal's count alone; the JSON's progress counts the stored poses too."""
    from accelcal_rig.store import read
    from accelcal_rig.web import campaigns as module

    for name in ("stall.h5", "stall.h5.journal"):
        shutil.copy(resumed / name, tmp_path / name)
    real_load = module.load_campaign

    def running(path: Path):  # noqa: ANN202 - as the module calls it
        campaign = real_load(path)
        campaign.state = "running"
        return campaign

    monkeypatch.setattr(module, "load_campaign", running)
    monkeypatch.setattr(read, "writer_liveness", lambda path, campaign: (True, "alive (pid 4242)"))
    monkeypatch.setattr(module, "holder", lambda path: "pid 4242")
    late = Progress(state="acquire", phase="poses", setpoint_c=35.0, setpoint_number=2, setpoints_total=2,
                    phase_elapsed_s=60.0, chamber_c=35.1, dut_c=(34.9, 35.0), poses_done=0, poses_total=12,
                    clock_s=6000.0, remaining_s=90.0)
    progress_path(tmp_path / "stall.h5").write_text(json.dumps({**late.__dict__, "line": late.line()}))
    summary = client(tmp_path).get("/api/campaigns/stall.h5").json()
    assert summary["poses_done"] == 12 and summary["progress"]["poses_done"] == 12
    assert "pose 12/12" in summary["progress"]["line"] and "pose 0/12" not in summary["progress"]["line"]
    page = client(tmp_path).get("/campaigns/stall.h5").text
    now = page.split('data-field="line">')[1].split("</td>")[0]
    assert now == "T35 (2/2) poses 0:01:00 · chamber 35.1 °C · DUT 34.90…35.00 °C · 0:01:30 left"
    assert page.count("12/12") == 1  # the poses row's


def test_an_unknown_campaign_is_a_styled_404_on_every_route_that_names_one(resumed: Path) -> None:
    app = create_app([resumed], None)
    routes = [r for r in app.routes if isinstance(r, Route) and "{name}" in r.path]
    assert len(routes) >= 3  # the page, its JSON, its files
    for route in routes:
        path = route.path.replace("{name}", "nope.h5").replace("{kind}", "report").replace("{file:path}", "index.html")
        answer = client(resumed).get(path)
        assert answer.status_code == 404, path
        if path.startswith("/api/"):
            assert answer.json() == {"error": "no campaign nope.h5 in the watched folders"}
        else:
            assert 'id="error-page"' in answer.text and "no campaign nope.h5 in the watched folders" in answer.text


def test_an_imu_campaign_shows_both_sensors_verdicts(imu_dry_run: tuple[Path, Path], tmp_path: Path) -> None:
    """An IMU's page and the list say each sensor's verdict, not only the DUT's combined one."""
    from tests.report.imu_campaign import copied

    campaign, _ = copied(imu_dry_run, tmp_path)
    app = client(tmp_path)
    (row,) = app.get("/api/campaigns").json()
    sensors = {serial: judged["sensors"] for serial, judged in row["verdicts"].items()}
    assert sensors and all(set(s) == {"accelerometer", "gyroscope"} for s in sensors.values())
    assert row["sensor_verdicts"].startswith("accelerometer ") and " · gyroscope " in row["sensor_verdicts"]
    for sensor in ("accelerometer", "gyroscope"):
        said = [s[sensor] for s in sensors.values()]
        counted = ", ".join(f"{said.count(v)} {v}" for v in ("FAIL", "CONDITIONAL", "PASS", "NOT JUDGED") if v in said)
        assert f"{sensor} {counted}" in row["sensor_verdicts"]
    assert row["sensor_verdicts"] in app.get("/").text
    page = app.get(f"/campaigns/{campaign.name}").text
    assert page.count('<ul class="sensors">') == len(sensors) and "<li>gyroscope <span class=\"verdict" in page
