"""Mending a campaign without losing a record: `rig repair`, and what every resume does first."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli import main
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.journal import read_journal
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import campaign_status, load_campaign, read_hdf5_campaign
from accelcal_rig.store.repair import repair_campaign
from tests.conftest import TINY_PROCEDURE, stored_poses


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


def test_a_lone_campaign_file_keeps_each_dut_its_own_data_when_it_gets_a_journal(write, workdir: Path) -> None:
    """DUTs listed in the rig config out of alphabetical order (the campaign file's groups are read in
    the campaign's order, not the alphabet's), aborted, the journal lost, resumed."""
    from accelcal_rig.errors import CampaignAborted
    from accelcal_rig.fit.sfem import distort
    from accelcal_rig.sim.truth import truth_for_serial
    from tests.engine.test_resume import TWO_SETPOINTS, run

    rig = (workdir / "sim.yaml").read_text()
    lines = [line for line in rig.splitlines() if "{serial: ADX355-A00" in line]
    write("sim.yaml", rig.replace("\n".join(lines), "\n".join(reversed(lines))))
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output, fail_at_pose=6)
    def by_serial(path: Path) -> dict[tuple[str, str], bytes]:
        return {(p.step_key, d.serial): d.channels["accel"].mean.tobytes() + d.channels["accel"].raw_codes.tobytes()
                for p in load_campaign(path).poses for d in p.duts}
    before = by_serial(output)
    journal_path(output).unlink()
    run(procedure, output, resume=True)
    after = by_serial(output)
    assert len(after) == 12 * 4 and all(after[key] == data for key, data in before.items())
    campaign = load_campaign(output)
    assert campaign.source == "journal" and campaign.notes == []
    for serial in campaign.serials:  # every DUT's data are its own: its simulated truth (fixed by its serial)
        true = truth_for_serial(serial).parameters_at(campaign.truth_column(serial, "temperature_c"))
        np.testing.assert_allclose(campaign.truth_column(serial, "parameters"), true, atol=1e-9)
        expected = distort(campaign.truth_column(serial, "gravity_g"), true)
        error = (np.abs(campaign.channel_column(serial, "accel", "mean") - expected)
                 / campaign.channel_column(serial, "accel", "stderr"))
        assert error.max() < 6, serial
    with h5py.File(output, "r") as f:
        soak = f["soaks/T20"]
        settled = dict(zip(list(f["duts"]), soak["settled_dut_c"][:]))
    for serial in campaign.serials:  # the soak columns follow the DUTs too
        assert abs(settled[serial] - campaign.dut_column(serial, "temperature_c")[0].mean()) < 0.5


def test_poses_only_the_campaign_file_still_holds_go_back_into_the_journal(campaign: Path) -> None:
    """The file one pose behind its journal, and one of the journal's pose records damaged: each holds five
    poses, between them all six are still there, and reading, then repairing, keeps all six."""
    from accelcal_rig.store.codec import replay
    from accelcal_rig.store.hdf5_file import campaign_image
    from accelcal_rig.store.journal import scan

    original = stored_poses(campaign)
    journal = journal_path(campaign)
    data = journal.read_bytes()
    poses = [r for r in scan(data).records if r.kind == "pose"]
    upto_fifth = data[:poses[4].offset + poses[4].size]
    campaign.write_bytes(campaign_image(replay(scan(upto_fifth), journal.name), len(upto_fifth)))  # one pose behind
    damaged = bytearray(data)
    damaged[poses[1].offset + 200] ^= 0xFF
    journal.write_bytes(bytes(damaged))
    status = campaign_status(campaign)
    assert status["poses_done"] == 6 and "c.h5.journal had lost 1 poses c.h5 still holds" in status["integrity"]
    assert status["campaign_file"].startswith("behind the journal: 5 of 6 poses")
    assert stored_poses(campaign) == original
    done = repair_campaign(campaign)
    assert "c.h5.journal had lost 1 poses c.h5 still holds: made again with them" in done[0]
    assert read_journal(journal).clean and len([r for r in read_journal(journal).records if r.kind == "pose"]) == 6
    assert stored_poses(campaign) == original and campaign_status(campaign)["integrity"] == "ok"
    assert measurements_sha256(read_hdf5_campaign(campaign)) == measurements_sha256(load_campaign(campaign))


def test_a_damaged_last_record_is_noted_set_aside_and_the_campaign_finished_again(campaign: Path, write) -> None:
    journal = journal_path(campaign)
    last = read_journal(journal).records[-1]
    assert last.kind == "state" and last.meta["state"] == "done"
    data = bytearray(journal.read_bytes())
    data[last.offset + 20] ^= 0x01
    journal.write_bytes(bytes(data))
    status = campaign_status(campaign)
    assert status["state"] == "running" and "bytes after its last whole record" in status["integrity"]
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), campaign, dry_run=True, seed=3, overwrite=False,
                 resume=True)
    status = campaign_status(campaign)
    assert (status["state"], status["poses_done"], status["integrity"]) == ("done", 6, "ok")
    kept = next(campaign.parent.glob("c.h5.journal.tail-*"))
    assert kept.read_bytes() == bytes(data[last.offset:])
