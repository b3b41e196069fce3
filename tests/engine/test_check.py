"""`rig check` says only what it asked: a chamber whose profile has no alarm query gets no word about an
alarm (never "clear"), one whose profile has it gets its answer."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from accelcal_rig.assembly import checked
from accelcal_rig.config.load import load_rig
from tests.conftest import SIM_RIG


def chamber_line(tmp_path: Path, driver: str, profile: str, **settings: object) -> str:
    """The one line `rig check --dry-run --only chamber` prints for a rig whose chamber speaks `profile`."""
    config = yaml.safe_load(SIM_RIG.read_text())
    config["chamber"].update(driver=driver, profile=profile, **settings)
    path = tmp_path / "rig.yaml"
    path.write_text(yaml.safe_dump(config))
    rig = load_rig(path)
    (chamber,) = checked(rig, dry_run=True, only=frozenset({"chamber"}))
    assert chamber.ok and chamber.name == "chamber", chamber.text
    return chamber.text


@pytest.mark.parametrize(("driver", "profile", "settings"), [
    ("line", "watlow-f4t-scpi", {}),  # the F4T's SCPI has no alarm query
    ("modbus-tcp", "watlow-f4t", {"registers": {"alarm_register": None}}),  # a map without its alarm register
])
def test_a_chamber_without_an_alarm_query_says_nothing_about_an_alarm(tmp_path: Path, driver: str, profile: str,
                                                                      settings: dict) -> None:
    line = chamber_line(tmp_path, driver, profile, **settings)
    assert line.startswith("tcp 127.0.0.1:") or line.startswith("modbus-tcp 127.0.0.1:")
    assert "°C); set point limits: the rig's" in line
    assert "alarm" not in line


@pytest.mark.parametrize(("driver", "profile"), [("line", "espec-p300"), ("modbus-tcp", "watlow-f4t")])
def test_a_chamber_with_an_alarm_query_says_its_answer(tmp_path: Path, driver: str, profile: str) -> None:
    assert "°C), alarm clear; set point limits: the rig's" in chamber_line(tmp_path, driver, profile)


def turntable_line(tmp_path: Path, **axis_settings: object) -> str:
    """The line `rig check --dry-run --only turntable` prints, the rig's inner axis given `axis_settings`."""
    config = yaml.safe_load(SIM_RIG.read_text())
    config["turntable"]["axes"][2].update(axis_settings)
    path = tmp_path / "rig.yaml"
    path.write_text(yaml.safe_dump(config))
    rig = load_rig(path)
    (turntable,) = checked(rig, dry_run=True, only=frozenset({"turntable"}))
    assert turntable.ok and turntable.name == "turntable", turntable.text
    return turntable.text


def test_a_table_reads_the_rate_of_the_axes_its_rig_gives_a_rate_mode_and_no_others(tmp_path: Path) -> None:
    assert "rate" not in turntable_line(tmp_path)  # the rig states no rate mode: nothing asked
    line = turntable_line(tmp_path, max_rate_dps=1000, max_acceleration_dps2=500)
    assert line.endswith("in position, rates inner 0.000 °/s")
