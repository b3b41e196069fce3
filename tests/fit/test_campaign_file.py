"""`rig fit`'s adapter: a campaign file fitted with its recorded options, overrides on top, refusals in one line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.fit.campaign_file import fit_campaign_file
from accelcal_rig.store.paths import journal_path


def copy_of(campaign: Path, folder: Path) -> Path:
    target = folder / campaign.name
    shutil.copy(campaign, target)
    shutil.copy(journal_path(campaign), journal_path(target))
    return target


def test_recorded_options_with_an_override(paper_campaign: Path, tmp_path: Path) -> None:
    campaign = copy_of(paper_campaign, tmp_path)
    before = campaign.read_bytes()
    outcome = fit_campaign_file(campaign, tmp_path / "cal.yaml", degree=2, mode=None)
    calibration = load_calibration(tmp_path / "cal.yaml")
    assert all(s.polynomial.degree == 2 for s in calibration.of_quantity("acceleration").values())  # the campaign records 3
    assert set(outcome.report) == set(calibration.of_quantity("acceleration")) and outcome.warnings == []
    assert campaign.read_bytes() == before  # only read


def test_a_folder_as_output_is_refused_naming_it(paper_campaign: Path, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=f"{tmp_path}: is a folder; name the calibration file to write"):
        fit_campaign_file(copy_of(paper_campaign, tmp_path), tmp_path)
