"""The live publisher (registry/publisher.py) on a board the test controls: the campaign's calls return at
once whatever the database does, writes are coalesced, a database that goes away is one warning and a retry
that loses no event, and a run whose campaign never started publishes nothing."""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from accelcal_rig.engine.progress import Progress
from accelcal_rig.registry.publisher import Identity, LivePublisher

DEADLINE_S = 30.0


class Board:
    """Records what is published; `down` makes every write fail; `gate` holds every write until set."""

    def __init__(self) -> None:
        self.begun: list[bool] = []
        self.rows: list[dict[str, Any]] = []
        self.events: list[str] = []
        self.points: list[float] = []
        self.down = False
        self.gate = threading.Event()
        self.gate.set()
        self.wrote = threading.Condition()

    def begin(self, key: str, row: dict[str, Any], fresh: bool) -> None:
        self._write()
        self.begun.append(fresh)

    def publish(self, key: str, row: dict[str, Any], events: Any = (), temperatures: Any = ()) -> None:
        self._write()
        with self.wrote:
            self.rows.append(row)
            self.events += [e.message for e in events]
            self.points += [t for t, _, _ in temperatures]
            self.wrote.notify_all()

    def _write(self) -> None:
        assert self.gate.wait(DEADLINE_S)
        if self.down:
            raise ConnectionError("server closed the connection")

    def wait_for(self, condition: Any) -> None:
        deadline = time.monotonic() + DEADLINE_S
        with self.wrote:
            while not condition():
                assert self.wrote.wait(max(0.0, deadline - time.monotonic())), "never published"


def _progress(poses: int, clock_s: float) -> Progress:
    return Progress("acquire", "poses", 25.0, 1, 3, 5.0, 25.1, (25.0, 25.2), poses, 100, clock_s, 600.0)


def _publisher(board: Board, **options: Any) -> LivePublisher:
    return LivePublisher("sqlite:////nowhere.sqlite", Identity("rig-a", Path("/data/a.h5"), "paper", True),
                         fresh=True, connect=lambda url: board, **options)


def test_progress_is_coalesced_and_the_last_word_published() -> None:
    board = Board()
    publisher = _publisher(board, interval_s=0.05)
    for pose in range(1, 2001):
        publisher(_progress(pose, pose * 30.0))
    publisher.event(5.0, "warning", "retry", "chamber: no reply")
    publisher.finish("done", 100, {"SN1": {"verdict": "PASS", "reasons": []}})
    assert publisher.close() is None
    assert board.begun == [True]
    assert len(board.rows) < 2000  # not a write per snapshot
    last = board.rows[-1]
    assert (last["state"], last["poses_done"], last["warnings"]) == ("done", 100, 1)
    assert last["verdicts"]["SN1"]["verdict"] == "PASS" and last["remaining_s"] is None
    assert board.events == ["chamber: no reply"]
    assert board.points == sorted(board.points) and all(b - a >= 60 for a, b in zip(board.points, board.points[1:]))


def test_the_campaign_never_waits_for_the_database() -> None:
    board = Board()
    board.gate.clear()  # every write hangs
    publisher = _publisher(board, interval_s=0.0)
    calls = threading.Thread(target=lambda: [publisher(_progress(k, k)) for k in range(5000)])
    calls.start()
    calls.join(DEADLINE_S)
    assert not calls.is_alive()  # 5000 snapshots handed over while the database answered nothing
    board.gate.set()
    publisher.finish("done", 5000)
    assert publisher.close() is None
    assert board.rows[-1]["poses_done"] == 5000


def test_a_database_that_goes_away_is_one_warning_and_loses_no_event(caplog: pytest.LogCaptureFixture,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    from accelcal_rig.registry import publisher as module

    monkeypatch.setattr(module, "RETRY_MAX_S", 0.05)
    board = Board()
    board.down = True
    publisher = _publisher(board, interval_s=0.0)
    with caplog.at_level(logging.INFO, logger="accelcal_rig"):
        for k in range(3):
            publisher(_progress(k, k))
            publisher.event(k, "info", "pose", f"pose {k}")
        deadline = time.monotonic() + DEADLINE_S
        while publisher.failures < 3:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        board.down = False
        board.wait_for(lambda: len(board.events) == 3)
        publisher.finish("done", 3)
        assert publisher.close() is None
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "server closed the connection; the campaign goes on, retrying" in warnings[0]
    assert any("takes it again" in r.getMessage() for r in caplog.records)
    assert board.events == ["pose 0", "pose 1", "pose 2"]


def test_a_database_down_at_the_end_is_said_in_one_line() -> None:
    board = Board()
    board.down = True
    publisher = _publisher(board, interval_s=0.0)
    publisher(_progress(1, 1.0))
    publisher.finish("aborted", 1, abort_reason="chamber alarm")
    problem = publisher.close(timeout_s=5.0)
    assert problem is not None and problem.startswith("live status: the campaign's last state did not reach")


def test_a_run_that_never_started_publishes_nothing() -> None:
    board = Board()
    publisher = _publisher(board)
    publisher.finish("aborted")
    assert publisher.close() is None
    assert board.begun == [] and board.rows == []
