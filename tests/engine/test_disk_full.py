"""A disk that fills up: the campaign stops in its safe state with every stored pose readable, and resumes
once there is space. The disk is made full in-process here (the file system calls fail with ENOSPC);
`bench/reliability.py diskfull` fills a real one."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest

from accelcal_rig import durable
from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.session import NothingToResume
from accelcal_rig.errors import CampaignAborted, DiskFull
from accelcal_rig.store import journal, writer
from accelcal_rig.store.read import campaign_status, load_campaign
from tests.conftest import stored_poses
from tests.engine.test_resume import TWO_SETPOINTS


class FullDisk:
    """From the `after`-th stored pose on, every allocation and file write fails as on a full disk."""

    def __init__(self, monkeypatch, after: int, free_after: int = 0) -> None:
        self.after, self.free_after, self.poses, self.full = after, free_after, 0, False
        monkeypatch.setattr(journal, "ALLOCATION_CHUNK_BYTES", 4096)  # the journal grows often
        real_allocate, real_write, real_append = journal._allocate, writer.write_atomically, writer.CampaignWriter.append_pose

        def allocate(fd, offset, length):
            if self.full:
                raise OSError(errno.ENOSPC, "No space left on device")
            real_allocate(fd, offset, length)

        def write_atomically(path, data, what):
            if self.full:
                raise DiskFull(f"no space left on {path.parent} (writing {what} {path.name})")
            real_write(path, data, what)

        def append_pose(self_, pose):
            real_append(self_, pose)
            self.poses += 1
            self.full = self.full or self.poses >= self.after

        monkeypatch.setattr(journal, "_allocate", allocate)
        monkeypatch.setattr(writer, "write_atomically", write_atomically)
        monkeypatch.setattr(durable, "write_atomically", write_atomically)  # the calibration too
        monkeypatch.setattr(writer.CampaignWriter, "append_pose", append_pose)
        monkeypatch.setattr(writer, "free_bytes", lambda folder: self.free_after if self.full else 10**12)


def safe_state_recorded(path: Path) -> bool:
    safe = [e.message for e in load_campaign(path).events if e.kind == "safe"]
    return (any("to 23 °C" in m for m in safe) and any("turntable" in m and "stop" in m for m in safe)
            and sum("standby" in m for m in safe) == 4)


@pytest.mark.parametrize("after", [1, 4, 7, 12])
def test_a_full_disk_stops_the_campaign_safely_and_it_resumes_once_there_is_space(write, workdir: Path, monkeypatch,
                                                                                  after: int) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    disk = FullDisk(monkeypatch, after)
    with monkeypatch.context():
        if after < 12:
            with pytest.raises(CampaignAborted, match=r"no space left on .*measuring stops"):
                run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False,
                             calibration=workdir / "c.calibration.yaml")
        else:  # the last pose stored, then the fit finds no room for the calibration
            result = run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False,
                                  calibration=workdir / "c.calibration.yaml")
            assert result.summary.fit_failed and "no space left on" in result.summary.fit
            assert result.problems and "is behind its journal (no space left on" in result.problems[0]
    stored = stored_poses(output)
    campaign = load_campaign(output)
    assert len(stored) >= after and campaign.state == ("done" if after == 12 else "aborted")
    assert safe_state_recorded(output)
    assert campaign_status(output)["integrity"] == "ok"
    disk.full = False
    monkeypatch.undo()  # space freed
    try:
        run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False, resume=True,
                     calibration=workdir / "c.calibration.yaml")
    except NothingToResume as complete:  # measured whole before the disk filled: its file and fit are mended
        assert "brought up to date from its journal; calibration → " in str(complete)
    status = campaign_status(output)
    assert (status["state"], status["poses_done"], status["campaign_file"]) == ("done", 12, "current")
    after_resume = stored_poses(output)
    assert all(after_resume[key] == data for key, data in stored.items())
    assert (workdir / "c.calibration.yaml").is_file()


def test_the_check_before_a_setpoint_stops_a_campaign_that_would_not_fit(write, workdir: Path, monkeypatch) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    monkeypatch.setattr(writer, "free_bytes", lambda folder: 10**12 if len(stored_poses(output)) < 6 else 50_000)
    with pytest.raises(CampaignAborted, match=r"not enough space left on .* for the rest of the campaign \(6 poses\): "
                                              r"0\.1 MB free, about \d+\.\d MB needed"):
        run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False)
    assert len(stored_poses(output)) == 6 and safe_state_recorded(output)


def test_a_campaign_the_disk_cannot_hold_is_refused_before_it_starts(write, workdir: Path, monkeypatch, capsys) -> None:
    from accelcal_rig.cli import main

    monkeypatch.setattr(durable, "free_bytes", lambda folder: 100_000)
    procedure = write("two.yaml", TWO_SETPOINTS)
    assert main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "c.h5: 0.1 MB free on" in err and "the campaign needs about" in err and "(1.5 × its estimated" in err
    assert not any(workdir.glob("c.h5*")) or sorted(p.name for p in workdir.glob("c.h5*")) == ["c.h5.lock"]
