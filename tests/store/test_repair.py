"""Mending a campaign without losing a record: `rig repair`, and what every resume does first."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.engine.session import prepare, run_campaign
from accelcal_rig.errors import ConfigError
from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.journal import read_journal
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import campaign_status, load_campaign, read_hdf5_campaign
from accelcal_rig.store.repair import repair_campaign
from tests.conftest import TINY_PROCEDURE, stored_poses


@pytest.fixture
def campaign(write, workdir: Path) -> Path:
    output = workdir / "c.h5"
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), output, dry_run=True, seed=3, overwrite=False)
    return output


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_lost_campaign_file_is_rebuilt_from_the_journal(campaign: Path) -> None:
    before = stored_poses(campaign)
    campaign.unlink()
    assert campaign_status(campaign)["campaign_file"].startswith("missing (rig repair")
    done = repair_campaign(campaign)
    assert done[-1].startswith("c.h5 rebuilt from its journal: 6 of 6 poses")
    assert stored_poses(campaign) == before and campaign_status(campaign)["campaign_file"] == "current"
    assert measurements_sha256(read_hdf5_campaign(campaign)) == measurements_sha256(load_campaign(campaign))


def test_a_damaged_journal_record_is_left_out_the_original_kept_and_its_pose_measured_again(
        campaign: Path, write, workdir: Path) -> None:
    journal = journal_path(campaign)
    poses = [r for r in read_journal(journal).records if r.kind == "pose"]
    data = bytearray(journal.read_bytes())
    data[poses[2].offset + 300] ^= 0x10  # one bit of the third pose's codes
    journal.write_bytes(bytes(data))
    campaign.unlink()  # and its campaign file gone too: the journal is all there is
    status = campaign_status(campaign)
    assert status["poses_done"] == 5 and "1 damaged stretches" in status["integrity"]
    done = repair_campaign(campaign)
    assert "1 damaged stretches" in done[0] and "the original kept as c.h5.journal.damaged-" in done[0]
    kept = next(workdir.glob("c.h5.journal.damaged-*"))
    assert kept.read_bytes() == bytes(data)  # nothing thrown away
    assert read_journal(journal).clean
    before = stored_poses(campaign)
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), campaign, dry_run=True, seed=3, overwrite=False,
                 resume=True)
    after = stored_poses(campaign)
    assert len(after) == 6 and all(after[k] == v for k, v in before.items())
    assert poses[2].meta["step_key"] in after  # measured again


def test_a_campaign_file_alone_gets_a_journal(campaign: Path) -> None:
    before = stored_poses(campaign)
    journal_path(campaign).unlink()
    assert campaign_status(campaign)["campaign_file"] == "the only copy (no journal)"
    done = repair_campaign(campaign)
    assert done[0] == "c.h5 had no journal: c.h5.journal made from its 6 poses"
    assert load_campaign(campaign).source == "journal" and stored_poses(campaign) == before


@pytest.mark.parametrize("damage", ["emptied", "edited"])
def test_a_damaged_campaign_file_without_a_journal_is_refused_and_left_alone(campaign: Path, damage: str,
                                                                              capsys) -> None:
    journal_path(campaign).unlink()
    with h5py.File(campaign, "r+") as f:
        data = f["duts/ADX355-A002/temperature_c"][()]
        del f["duts/ADX355-A002/temperature_c"]
        f["duts/ADX355-A002/temperature_c"] = data[:0] if damage == "emptied" else np.roll(data, 1, axis=0)
    before = digest(campaign)
    expected = ("duts/ADX355-A002/temperature_c has 0 rows" if damage == "emptied"
                else "do not match the digest written with them")
    for argv in (["repair", str(campaign)], ["resume", str(campaign)], ["fit", str(campaign), "-o", "x.yaml"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and expected in err, (argv, err)
    assert digest(campaign) == before and not journal_path(campaign).exists()
    assert expected in campaign_status(campaign)["integrity"]


def test_a_journal_of_another_campaign_is_refused(campaign: Path, write, workdir: Path) -> None:
    other = workdir / "other.h5"
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), other, dry_run=True, seed=4, overwrite=False)
    shutil.copy(journal_path(other), journal_path(campaign))
    with pytest.raises(ConfigError, match="it and its journal hold different campaigns"):
        load_campaign(campaign)
    with pytest.raises(ConfigError, match="hold different campaigns .*nothing was changed"):
        repair_campaign(campaign)


def test_a_pose_stored_twice_is_reported_and_kept_once(campaign: Path) -> None:
    journal = journal_path(campaign)
    poses = [r for r in read_journal(journal).records if r.kind == "pose"]
    data = journal.read_bytes()
    journal.write_bytes(data + data[poses[1].offset:poses[1].offset + poses[1].size])
    status = campaign_status(campaign)
    assert status["poses_done"] == 6 and "pose T30/pose02 stored more than once" in status["integrity"]
    repair_campaign(campaign)
    with h5py.File(campaign, "r") as f:
        keys = [k.decode() for k in f["poses/step_key"][:]]
    assert sorted(keys) == sorted(set(keys)) and len(keys) == 6
