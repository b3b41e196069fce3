"""A lot is what the lab calls a lot: a DUT's fixture entry names it (`lot:`), else `rig run --lot`; it is
recorded on each calibration and shown in the registry, and the part's page is titled by its part."""

from __future__ import annotations

from pathlib import Path

import yaml
from starlette.testclient import TestClient

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app
from tests.conftest import REPO, SIM_RIG
from tests.test_cli import rig


def test_a_dut_s_own_lot_else_the_run_s_is_recorded_and_shown(tmp_path: Path) -> None:
    config = yaml.safe_load(SIM_RIG.read_text())
    config["fixture"]["sensors"][0]["lot"] = "INC-2026-118"
    (tmp_path / "sim.yaml").write_text(yaml.safe_dump(config))
    registry = normalised(str(tmp_path / "lab.sqlite"))
    run = rig("run", str(REPO / "procedures" / "quick-6pos.yaml"), "--config", "sim.yaml", "--dry-run", "-o", "q.h5",
              "--registry", registry, "--no-pdf", "--no-publish", "--lot", "W47-A", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    lots = {row["serial"]: row["lot"] for row in Registry.open(registry).calibrations()}
    first = config["fixture"]["sensors"][0]["serial"]
    assert lots.pop(first) == "INC-2026-118" and set(lots.values()) == {"W47-A"}
    client = TestClient(create_app([tmp_path], registry), base_url="http://127.0.0.1")
    page = client.get("/registry").text
    assert "<th>lot</th>" in page and "INC-2026-118" in page and "W47-A" in page
    assert "<h1>Part: adxl355</h1>" in client.get("/registry/parts/adxl355").text


def test_a_lot_that_is_not_one_line_is_refused(tmp_path: Path) -> None:
    run = rig("run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", "q.h5", "--lot", "a\nb",
              cwd=tmp_path)
    assert run.returncode == 2 and "--lot: not one line of at most 64 characters" in run.stderr
    assert not (tmp_path / "q.h5").exists()
