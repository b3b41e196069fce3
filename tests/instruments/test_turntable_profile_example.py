"""The worked example of docs/instruments.md ("Writing a profile for another controller") is a working
profile: the block is read from the document, its simulator made from it, and a quick campaign run on it."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from accelcal_rig.cli import main
from accelcal_rig.config.rig import TurntableConfig
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO, SIM_RIG


def documented_turntable() -> dict:
    text = (REPO / "docs" / "instruments.md").read_text()
    section = text.split("### Writing a profile for another controller", 1)[1]
    block = re.search(r"```yaml\n(.*?)```", section, re.S)
    assert block is not None, "the worked example's YAML block is missing"
    return yaml.safe_load(block.group(1))["turntable"]


def test_the_documented_profile_validates_and_says_what_the_manual_says() -> None:
    config = TurntableConfig.model_validate(documented_turntable())
    protocol = config.line_protocol()
    assert protocol.write_terminator == "\r" and protocol.multi_axis_move
    assert protocol.move.send.format(axis=2, angle=-45.0) == "2PA-45.0000" and protocol.move.reply is None
    assert protocol.busy is not None and protocol.busy.per_axis and protocol.busy_values == ["0"]
    assert re.fullmatch(protocol.fault.reply or "", "108, 451322, MOTOR / STAGE NOT CONNECTED")


def test_a_quick_campaign_runs_on_the_documented_profile(tmp_path: Path, capsys) -> None:
    rig = yaml.safe_load(SIM_RIG.read_text())
    rig["turntable"] = {**documented_turntable(), "endpoint": None}
    (tmp_path / "sim.yaml").write_text(yaml.safe_dump(rig))
    procedure = tmp_path / "quick.yaml"
    procedure.write_text((REPO / "procedures" / "quick-6pos.yaml").read_text().replace("../configs/sim.yaml", "sim.yaml"))
    assert main(["run", str(procedure), "--dry-run", "-o", str(tmp_path / "q.h5"), "-q", "--no-pdf"]) == 0
    stored = load_campaign(tmp_path / "q.h5")
    assert stored.state == "done" and len(stored.poses) == 12
    assert any("turntable:" in e.message and "simulated turntable" in e.message for e in stored.events)
