"""The live tables (registry/live.py) on SQLite and PostgreSQL: a campaign's row replaced as it publishes, its
events and temperatures added, silence judged on the database's clock, a new campaign in the same file
starting afresh and a resumed one continuing."""

from __future__ import annotations

from datetime import datetime, timedelta

import pytest
import sqlalchemy as sa

from accelcal_rig.registry import live
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.live import LiveBoard, LiveEvent, campaign_key
from accelcal_rig.registry.schema import live_campaigns


def _row(**changes: object) -> dict:
    row = {"rig": "rig-a", "host": "bench-1", "campaign": "/data/a.h5", "procedure": "paper", "dry_run": True,
           "pid": 42, "state": "running", "phase": "soak", "setpoint_c": -40.0, "setpoint_number": 1,
           "setpoints_total": 14, "poses_done": 0, "poses_total": 432, "chamber_c": -39.9, "dut_c": [-39.5],
           "remaining_s": 3600.0, "clock_s": 10.0, "line": "T-40 (1/14) soak", "warnings": 0, "errors": 0,
           "verdicts": {}, "findings": [], "abort_reason": "", "started_at": datetime(2026, 12, 1, 20, 0)}
    row.update(changes)
    return row


def _event(message: str, level: str = "info") -> LiveEvent:
    return LiveEvent(1.0, datetime(2026, 12, 1, 20, 1), level, "soak", message)


def test_a_campaign_publishes_its_row_events_and_temperatures(registry_url: str) -> None:
    board = LiveBoard(Registry.open(registry_url))
    key = campaign_key("bench-1", "/data/a.h5")
    board.begin(key, _row(), fresh=True)
    board.publish(key, _row(poses_done=8, phase="poses"), [_event("first"), _event("retry", "warning")],
                  [(60.0, -39.9, -39.5), (120.0, -40.0, None)])
    [row] = board.campaigns()
    assert (row["key"], row["poses_done"], row["phase"], row["stale"]) == (key, 8, "poses", False)
    assert row["silent_s"] < 30  # written on the database's clock, read beside it
    assert [e.message for e in board.events(key)] == ["first", "retry"]
    series = board.temperatures(key)
    assert series["t_h"] == [60 / 3600, 120 / 3600] and series["chamber_c"] == [-39.9, -40.0]
    assert series["dut_c"][0] == -39.5 and series["dut_c"][1] != series["dut_c"][1]  # missing: NaN
    assert board.campaign("0" * 32) is None


def test_a_running_campaign_silent_too_long_is_stale_and_an_ended_one_never(registry_url: str) -> None:
    board = LiveBoard(Registry.open(registry_url))
    board.begin("a" * 32, _row(), fresh=True)
    board.begin("b" * 32, _row(rig="rig-b", state="done"), fresh=True)
    with board.engine.begin() as connection:  # both last heard of a minute before the database's now
        connection.execute(sa.update(live_campaigns).values(updated_at=board.now() - timedelta(seconds=60)))
    found = {row["key"]: row for row in board.campaigns()}
    assert found["a" * 32]["stale"] and found["a" * 32]["silent_s"] > live.STALE_AFTER_S
    assert not found["b" * 32]["stale"]
    board.publish("a" * 32, _row())  # heard from again
    assert not board.campaign("a" * 32)["stale"]


def test_a_new_campaign_in_the_file_starts_afresh_and_a_resumed_one_continues(registry_url: str) -> None:
    board = LiveBoard(Registry.open(registry_url))
    key = "c" * 32
    board.begin(key, _row(), fresh=True)
    board.publish(key, _row(), [_event("run 1")], [(60.0, 1.0, 1.0)])
    board.begin(key, _row(), fresh=False)
    board.publish(key, _row(), [_event("run 2")])
    assert [e.message for e in board.events(key)] == ["run 1", "run 2"]
    board.begin(key, _row(), fresh=True)
    assert board.events(key) == [] and board.temperatures(key)["t_h"] == []
    assert len(board.campaigns()) == 1


def test_events_kept_are_the_newest(registry_url: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(live, "EVENTS_KEPT", 5)
    board = LiveBoard(Registry.open(registry_url))
    board.begin("d" * 32, _row(), fresh=True)
    for k in range(3):
        board.publish("d" * 32, _row(), [_event(f"{k}-{n}") for n in range(3)])
    assert [e.message for e in board.events("d" * 32)] == ["1-1", "1-2", "2-0", "2-1", "2-2"]


def test_postgresql_announces_every_publish(postgresql_url: str) -> None:
    import psycopg

    board = LiveBoard(Registry.open(postgresql_url))
    address = sa.engine.make_url(postgresql_url).set(drivername="postgresql").render_as_string(hide_password=False)
    with psycopg.connect(address, autocommit=True) as listener:
        listener.execute("LISTEN accelcal_live")
        board.begin("e" * 32, _row(), fresh=True)
        board.publish("e" * 32, _row(poses_done=1))
        heard = [n.payload for n in listener.notifies(timeout=10, stop_after=2)]
    assert heard[:2] == ["e" * 32, "e" * 32]
