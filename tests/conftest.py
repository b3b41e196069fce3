"""Shared fixtures: the shipped files, and tiny procedures written next to a copy of the sim rig."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SIM_RIG = REPO / "configs" / "sim.yaml"

TINY_PROCEDURE = """\
name: tiny
rig: sim.yaml
setpoints_c: [30]
soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}
schedule: {kind: six-position}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
"""


@pytest.fixture(scope="session", autouse=True)
def test_registry(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Every finished fit in the tests (and in the processes they start) is recorded in a registry of the
    session's own, never in the user's: a dry run's in the session's dry runs' registry beside it."""
    import os

    path = tmp_path_factory.mktemp("registry") / "registry.sqlite"
    os.environ["ACCELCAL_REGISTRY"] = str(path)
    os.environ["ACCELCAL_DRY_RUN_REGISTRY"] = str(path.with_name("dry-runs.sqlite"))
    return path


@pytest.fixture
def workdir(tmp_path: Path) -> Path:
    """A folder holding a copy of the simulated rig config, for procedures that name `rig: sim.yaml`."""
    shutil.copy(SIM_RIG, tmp_path / "sim.yaml")
    return tmp_path


@pytest.fixture
def write(workdir: Path):
    def _write(name: str, text: str) -> Path:
        path = workdir / name
        path.write_text(text)
        return path

    return _write


@pytest.fixture(scope="session")
def paper_campaign(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One dry run of the paper campaign (11 × 24 poses, 4 DUTs), shared by the tests that only read it."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare

    output = tmp_path_factory.mktemp("paper") / "campaign.h5"
    run_campaign(prepare(REPO / "procedures" / "paper-24pos-thermal.yaml"), output, dry_run=True, seed=0,
                 overwrite=False)
    return output


@pytest.fixture(scope="session")
def fitted_paper_campaign(paper_campaign: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A copy of the paper campaign with its fit done: (campaign file, calibration file)."""
    from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save
    from accelcal_rig.store.read import load_campaign

    folder = tmp_path_factory.mktemp("fitted")
    campaign, calibration = folder / "campaign.h5", folder / "campaign.calibration.yaml"
    shutil.copy(paper_campaign, campaign)
    fit_and_save(load_campaign(campaign), campaign, calibration, FitOptions())
    return campaign, calibration


def kill_mid_pose(campaign: Path, keep_poses: int) -> int:
    """Leave the campaign's journal as `kill -9` in the middle of storing pose `keep_poses + 1` would: whole
    up to the record of pose `keep_poses`, then half of the next pose's record. Returns that half's bytes."""
    from accelcal_rig.store.codec import replay
    from accelcal_rig.store.hdf5_file import campaign_image
    from accelcal_rig.store.journal import scan
    from accelcal_rig.store.paths import journal_path

    journal = journal_path(campaign)
    data = journal.read_bytes()
    poses = [r for r in scan(data).records if r.kind == "pose"]
    kept, cut = poses[keep_poses - 1], poses[keep_poses]
    whole = data[:kept.offset + kept.size]
    torn = data[cut.offset:cut.offset + cut.size // 2]
    journal.write_bytes(whole + torn)
    # The campaign file is never ahead of its journal: leave it as it was built from the last whole record.
    campaign.write_bytes(campaign_image(replay(scan(whole), journal.name), len(whole)))
    return len(torn)


def _channels_bytes(dut) -> bytes:  # noqa: ANN001 (a DutPoseRecord)
    """A DUT's pose record's channels (codes, means, standard errors, references) as bytes."""
    return b"".join(c.raw_codes.tobytes() + c.mean.tobytes() + c.stderr.tobytes() + c.reference.tobytes()
                    for c in dut.channels.values())


def stored_poses(campaign: Path) -> dict[str, bytes]:
    """Every stored pose's data as bytes, by step key (to compare before and after)."""
    from accelcal_rig.store.read import load_campaign

    loaded = load_campaign(campaign)
    return {p.step_key: b"".join([p.commanded_angles_deg.tobytes(), p.measured_angles_deg.tobytes(),
                                  repr((p.setpoint_c, p.t_start_s, p.t_end_s, p.chamber_temperature_c)).encode()]
                                 + [_channels_bytes(d)
                                    + repr(d.temperature_c).encode() for d in p.duts])
            for p in loaded.poses}


@pytest.fixture(scope="session")
def imu_dry_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The small IMU campaign (tests/fit/test_gyro_fit.py's PROCEDURE, seed 3), run once and fitted as `rig run`
    fits it: (campaign, calibration). Modules take a copy of it (tests/report/imu_campaign.py's `copied`)."""
    from tests.report.imu_campaign import imu_campaign

    return imu_campaign(tmp_path_factory.mktemp("imu-session"))
