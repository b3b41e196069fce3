"""`rig run` publishes its campaign's live status to the registry its calibrations go to: as it runs, and its
last word (done, its poses, each DUT's verdict); `--no-publish` publishes nothing; a registry that cannot be
reached is a warning, never a failed campaign."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli.outcome import EXIT_NOT_RECORDED
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.live import LiveBoard
from accelcal_rig.registry.location import normalised
from tests.conftest import REPO
from tests.test_cli import rig

QUICK = str(REPO / "procedures" / "quick-6pos.yaml")


def test_a_run_publishes_its_progress_events_and_verdicts(tmp_path: Path) -> None:
    registry = tmp_path / "lab.sqlite"
    run = rig("run", QUICK, "--dry-run", "-o", "quick.h5", "--registry", str(registry), "--no-pdf", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    board = LiveBoard(Registry.open(normalised(str(registry))))
    [row] = board.campaigns()
    assert row["state"] == "done" and row["campaign"] == str((tmp_path / "quick.h5").resolve())
    assert row["poses_done"] == row["poses_total"] > 0 and row["rig"] == "simulated-rig" and row["dry_run"]
    assert set(row["verdicts"]) == {"ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"}
    events = [e.message for e in board.events(row["key"])]
    assert any(m.startswith("safe state") for m in events) and any("poses stored" in m for m in events)
    assert board.temperatures(row["key"])["t_h"]


def test_no_publish_publishes_nothing(tmp_path: Path) -> None:
    registry = tmp_path / "lab.sqlite"
    run = rig("run", QUICK, "--dry-run", "-o", "quick.h5", "--registry", str(registry), "--no-pdf", "--no-publish",
              cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert LiveBoard(Registry.open(normalised(str(registry)))).campaigns() == []


def test_a_registry_that_cannot_be_reached_is_a_warning_not_a_failure(tmp_path: Path) -> None:
    run = rig("run", QUICK, "--dry-run", "-o", "quick.h5", "--registry", "postgresql://nobody@127.0.0.1:1/lab",
              "--no-pdf", cwd=tmp_path)
    assert run.returncode == EXIT_NOT_RECORDED, run.stderr   # the campaign stands; its rows wait for a resume
    assert "campaign done" in run.stdout
    lines = [line for line in run.stderr.splitlines() if "live status" in line]
    assert len(lines) == 2, run.stderr  # the first failure, and the last word that did not get there
    assert "the campaign goes on, retrying" in lines[0] and "127.0.0.1" in lines[0]
    assert lines[1].startswith("rig: warning: live status: the campaign's last state did not reach")


def test_an_interrupt_while_the_last_word_is_published_is_one_line(tmp_path: Path, monkeypatch, capsys) -> None:
    """Ctrl-C after the campaign ended, while its live status is closing (a slow database): one warning line,
    and the command's own outcome stands (nothing raised out of it)."""
    from types import SimpleNamespace

    from accelcal_rig.cli import campaign as cli_campaign
    from accelcal_rig.registry import publisher

    class Interrupted:
        def __init__(self, *args: object) -> None:
            self.started, self.finished = True, True

        def handler(self):
            import logging

            return logging.NullHandler()

        def close(self) -> str | None:
            raise KeyboardInterrupt

    monkeypatch.setattr(publisher, "LivePublisher", Interrupted)
    prepared = SimpleNamespace(rig=SimpleNamespace(model=SimpleNamespace(registry=None, name="rig-a"), path=tmp_path / "r.yaml"),
                               procedure=SimpleNamespace(model=SimpleNamespace(name="p")))
    follow_up = SimpleNamespace(registry=str(tmp_path / "lab.sqlite"))
    with cli_campaign.live_publishing(prepared, tmp_path / "c.h5", follow_up, dry_run=True, fresh=True,  # type: ignore[arg-type]
                                      enabled=True) as live:
        assert isinstance(live, Interrupted)
    assert capsys.readouterr().err.strip() == ("rig: warning: live status: interrupted before the campaign's last state "
                                               "was published (its campaign file has it)")
