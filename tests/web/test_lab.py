"""The lab's rigs on the dashboard (web/lab.py, web/rigs.py): one card per rig in each of its states, the
recent campaigns of every rig, a published campaign's page, and the event stream that tells a page to look
again."""

from __future__ import annotations

import re
from datetime import datetime, timedelta
from pathlib import Path

import pytest
import sqlalchemy as sa
from starlette.testclient import TestClient

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.live import LiveBoard, LiveEvent
from accelcal_rig.registry.location import normalised
from accelcal_rig.registry.schema import live_campaigns
from accelcal_rig.web import lab as lab_module
from accelcal_rig.web.app import create_app
from tests.registry.test_live import _row


@pytest.fixture
def published(tmp_path: Path) -> tuple[str, LiveBoard]:
    """Five rigs, one in each state a card shows."""
    url = normalised(str(tmp_path / "registry.sqlite"))
    board = LiveBoard(Registry.open(url))
    rows = {
        "1" * 32: _row(rig="rig-run", poses_done=108, remaining_s=7200.0, line="T-20 (2/14) poses"),
        "2" * 32: _row(rig="rig-dead", host="bench-2", poses_done=30),
        "3" * 32: _row(rig="rig-abort", state="aborted", abort_reason="chamber alarm: door open"),
        "4" * 32: _row(rig="rig-done", state="done", poses_done=432, remaining_s=None,
                       verdicts={"SN1": {"verdict": "PASS", "reasons": []},
                                 "SN2": {"verdict": "FAIL", "reasons": ["bias x 30 mg, limit ±25 mg: fail"]}}),
        "5" * 32: _row(rig="rig-idle", state="done", findings=["DUT SN9 at -40 °C: residuals 40× its noise"]),
    }
    for key, row in rows.items():
        board.begin(key, row, fresh=True)
    board.publish("1" * 32, rows["1" * 32], [LiveEvent(5.0, datetime(2026, 12, 1, 20, 1), "warning", "retry",
                                                       "chamber (modbus-tcp 10.0.0.7:502): no reply; attempt 1 of 3")],
                  [(60.0, -20.0, -19.8)])
    with board.engine.begin() as connection:
        now = board.now()
        connection.execute(sa.update(live_campaigns).where(live_campaigns.c.key == "2" * 32)
                           .values(updated_at=now - timedelta(seconds=90)))
        connection.execute(sa.update(live_campaigns).where(live_campaigns.c.key == "5" * 32)
                           .values(updated_at=now - timedelta(days=2)))
    return url, board


def test_one_card_per_rig_says_how_it_stands(published: tuple[str, LiveBoard], tmp_path: Path) -> None:
    url, _ = published
    client = TestClient(create_app([tmp_path], url), base_url="http://127.0.0.1")
    cards = {c["rig"]: c for c in client.get("/api/rigs").json()["rigs"]}
    assert {rig: c["status"] for rig, c in cards.items()} == {
        "rig-run": "running", "rig-dead": "silent", "rig-abort": "aborted", "rig-done": "done", "rig-idle": "idle"}
    assert cards["rig-run"]["headline"] == "running · 108/432 poses · 2:00:00 left"
    assert cards["rig-run"]["campaign"]["percent"] == 25.0
    assert re.fullmatch(r"not heard from since \S+ \S+ UTC \(2 min ago\)", cards["rig-dead"]["headline"])
    assert cards["rig-abort"]["headline"] == "aborted: chamber alarm: door open"
    assert cards["rig-done"]["headline"] in ("done · 1 PASS, 1 FAIL", "done · 1 FAIL, 1 PASS")
    page = client.get("/").text
    assert page.count('class="card status-') == 5 and "rig-dead" in page and "bench-2" in page
    assert "SN2 FAIL" in page and "not heard from since" in page
    fragment = client.get("/fragments/rigs").text
    assert fragment.count('class="card status-') == 5 and "<html" not in fragment


def test_a_published_campaign_has_its_page(published: tuple[str, LiveBoard], tmp_path: Path) -> None:
    url, _ = published
    client = TestClient(create_app([tmp_path], url), base_url="http://127.0.0.1")
    page = client.get("/live/" + "1" * 32)
    assert page.status_code == 200
    assert "rig-run" in page.text and "T-20 (2/14) poses" in page.text and "<svg" in page.text
    assert "no reply" in page.text and "recovered" in page.text  # the retry grouped, and it went on
    data = client.get("/api/live/" + "4" * 32).json()
    assert data["verdicts"]["SN2"]["verdict"] == "FAIL" and data["status"] == "done"
    for wrong in ("0" * 32, "not-a-key", "1" * 31):
        missing = client.get("/live/" + wrong)
        assert missing.status_code == 404 and "<html" in missing.text  # the styled page


def test_without_a_registry_yet_the_front_page_says_so(tmp_path: Path) -> None:
    client = TestClient(create_app([tmp_path], normalised(str(tmp_path / "none.sqlite"))), base_url="http://127.0.0.1")
    page = client.get("/")
    assert page.status_code == 200 and "rigs: registry" in page.text and "does not exist" in page.text
    assert client.get("/api/rigs").status_code == 503
    assert not (tmp_path / "none.sqlite").exists()  # a page never creates a registry


def test_the_event_stream_says_when_something_changed(published: tuple[str, LiveBoard], tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(lab_module, "STREAM_S", 2.5)  # the stream ends by itself: the test reads all of it
    monkeypatch.setattr(lab_module, "TICK_S", 0.5)
    url, _ = published
    client = TestClient(create_app([tmp_path], url), base_url="http://127.0.0.1")
    with client.stream("GET", "/api/live/stream") as response:
        assert response.headers["content-type"].startswith("text/event-stream")
        text = "".join(response.iter_text())
    assert text.startswith("retry: ") and "event: change" in text and "event: tick" in text


def test_a_card_whose_campaign_file_says_done_shows_done(tmp_path: Path) -> None:
    """A run whose last update never reached the registry (a kill after the last pose, the registry down at the
    end) left its card "running" and then silent: a dashboard that watches the campaign's folder shows it as its
    file says; one that does not, or a campaign of another computer, still says it was not heard from."""
    from accelcal_rig.cli import main
    from tests.conftest import REPO

    folder, elsewhere = tmp_path / "campaigns", tmp_path / "elsewhere"
    folder.mkdir(), elsewhere.mkdir()
    url = normalised(str(tmp_path / "registry.sqlite"))
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(folder / "quick.h5"),
                 "-q", "--no-pdf", "--registry", url]) == 0
    board = LiveBoard(Registry.open(url))
    with board.engine.begin() as connection:  # the end never published: running, last heard 10 min ago
        connection.execute(sa.update(live_campaigns).values(state="running", poses_done=3, verdicts={},
                                                            updated_at=board.now() - timedelta(minutes=10)))
    [card] = TestClient(create_app([folder], url), base_url="http://127.0.0.1").get("/api/rigs").json()["rigs"]
    assert card["status"] == "done", card
    assert card["headline"] == "done · 4 NOT JUDGED (its campaign file says so)"   # the file's (no limits)
    assert card["campaign"]["poses_done"] == card["campaign"]["poses_total"] > 3
    assert "its end never reached the registry" in card["campaign"]["from_file"]
    page = TestClient(create_app([folder], url), base_url="http://127.0.0.1").get("/").text
    assert "its campaign file says so" in page and "not heard from since" not in page

    [unwatched] = TestClient(create_app([elsewhere], url), base_url="http://127.0.0.1").get("/api/rigs").json()["rigs"]
    assert unwatched["status"] == "silent"
    with board.engine.begin() as connection:
        connection.execute(sa.update(live_campaigns).values(host="another-computer"))
    [other] = TestClient(create_app([folder], url), base_url="http://127.0.0.1").get("/api/rigs").json()["rigs"]
    assert other["status"] == "silent"
