"""The small IMU campaign of tests/fit/test_gyro_fit.py, run and fitted for the output tests: its campaign file,
and its calibration beside it where `rig report` and `rig registry add` look (FILE.calibration.yaml)."""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save
from accelcal_rig.store.read import load_campaign
from tests.fit.test_gyro_fit import PROCEDURE


def imu_campaign(folder: Path) -> tuple[Path, Path]:
    """(campaign, calibration) of a dry run of the small IMU campaign (seed 3), fitted as `rig run` fits it.
    A minute of dry run: the tests share one (tests/conftest.py's `imu_dry_run`) through `copied`."""
    procedure = folder / "imu.yaml"
    procedure.write_text(yaml.safe_dump(PROCEDURE, sort_keys=False))
    campaign = folder / "imu.h5"
    run_campaign(prepare(procedure), campaign, dry_run=True, seed=3, overwrite=False)
    calibration = campaign.with_suffix(".calibration.yaml")
    fit_and_save(load_campaign(campaign), campaign, calibration, FitOptions(degree=1))
    return campaign, calibration


def copied(built: tuple[Path, Path], folder: Path) -> tuple[Path, Path]:
    """A copy of a built IMU campaign (its campaign file, journal and calibration) in `folder`, for a test module
    to use as its own: what one module does to its copy no other sees."""
    campaign, calibration = built
    for path in campaign.parent.glob(campaign.name + "*"):
        if path.is_file() and not path.name.endswith(".lock"):
            shutil.copy(path, folder / path.name)
    shutil.copy(calibration, folder / calibration.name)
    return folder / campaign.name, folder / calibration.name
