"""The disk a campaign needs, known before it starts, against what the paper campaign's dry run wrote."""

from __future__ import annotations

from pathlib import Path

import pytest

from accelcal_rig.engine.preparation import prepare
from accelcal_rig.store.paths import journal_path
from tests.conftest import REPO


def test_the_estimate_is_within_a_fifth_of_the_files_written(paper_campaign: Path) -> None:
    estimate = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml").storage(dry_run=True)
    assert estimate.journal_bytes == pytest.approx(journal_path(paper_campaign).stat().st_size, rel=0.2)
    assert estimate.file_bytes == pytest.approx(paper_campaign.stat().st_size, rel=0.2)
    assert estimate.need_bytes > journal_path(paper_campaign).stat().st_size + 2 * paper_campaign.stat().st_size
    assert estimate.remaining_bytes(0) < estimate.remaining_bytes(100) < estimate.need_bytes


def test_a_six_axis_duts_pose_costs_its_channels_in_the_estimate() -> None:
    """The disk estimate counts every channel of every DUT: four IMUs' poses take about twice the bytes of
    four accelerometers' (the gyroscope's codes beside the accelerometer's), not the same."""
    from accelcal_rig.store.space import pose_record_bytes

    accelerometers = pose_record_bytes(4, 200, 3, True)
    imus = pose_record_bytes(4, 200, 3, True, [(("accel", 3), ("gyro", 3))] * 4)
    assert 1.8 < imus / accelerometers < 2.0
