"""A tiny dry-run campaign (6 poses, seed 3) for the store's tests to read, damage and mend."""

from __future__ import annotations

from pathlib import Path

import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from tests.conftest import TINY_PROCEDURE


@pytest.fixture
def campaign(write, workdir: Path) -> Path:
    output = workdir / "c.h5"
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), output, dry_run=True, seed=3, overwrite=False)
    return output
