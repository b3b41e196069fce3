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
    from accelcal_rig.engine.session import prepare, run_campaign

    output = tmp_path_factory.mktemp("paper") / "campaign.h5"
    run_campaign(prepare(REPO / "procedures" / "paper-24pos-thermal.yaml"), output, dry_run=True, seed=0,
                 overwrite=False)
    return output


@pytest.fixture(scope="session")
def fitted_paper_campaign(paper_campaign: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A copy of the paper campaign with its fit done: (campaign file, calibration file)."""
    import h5py

    from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save

    folder = tmp_path_factory.mktemp("fitted")
    campaign, calibration = folder / "campaign.h5", folder / "campaign.calibration.yaml"
    shutil.copy(paper_campaign, campaign)
    with h5py.File(campaign, "a") as file:
        fit_and_save(file, campaign, calibration, FitOptions())
    return campaign, calibration
