"""A serial is an identifier wherever it enters: a rig config, a calibration file, `fit-recording --serial` or a
recording's file name; a path, a control character or `..` is refused in one line naming where it came from,
before anything is written or recorded."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.cli import main
from accelcal_rig.config.load import load_rig
from accelcal_rig.core.identifiers import checked_serial, is_serial
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import load_calibration
from tests.conftest import SIM_RIG
from tests.handheld.test_gyro import COLUMNS, gyro_session

HOSTILE = ["../../etc/passwd", "..", ".hidden", "-x", "a/b", "a\\b", "tab\there", "line\nbreak", "", "x" * 65]


@pytest.mark.parametrize("serial", HOSTILE)
def test_what_is_no_serial_is_refused_naming_where_it_came_from(serial: str) -> None:
    assert not is_serial(serial)
    with pytest.raises(ConfigError, match=r"^--serial: serial .* is not an identifier") as caught:
        checked_serial(serial, "--serial")
    assert "\n" not in str(caught.value)


def test_serials_a_lab_uses_are_identifiers() -> None:
    assert all(map(is_serial, ["ADX355-A001", "IMU-F015", "T010", "SN_0042.b", "x" * 64]))


def test_a_rig_config_refuses_them(tmp_path: Path) -> None:
    rig = yaml.safe_load(SIM_RIG.read_text())
    rig["fixture"]["sensors"][0]["serial"] = ".."
    (tmp_path / "rig.yaml").write_text(yaml.safe_dump(rig))
    with pytest.raises(ConfigError, match=r"fixture.sensors\[0\].serial: String should match pattern"):
        load_rig(tmp_path / "rig.yaml")


def test_fit_recording_refuses_a_serial_that_is_a_path(tmp_path: Path, capsys) -> None:
    path = gyro_session(np.random.default_rng(3)).write(tmp_path / "s.csv")
    argv = ["fit-recording", str(path), "--columns", COLUMNS, "-o", str(tmp_path / "cal.yaml"),
            "--registry", str(tmp_path / "registry.sqlite")]
    assert main([*argv, "--serial", "../../etc/passwd"]) == 2
    assert "--serial: serial '../../etc/passwd' is not an identifier" in capsys.readouterr().err
    assert not (tmp_path / "cal.yaml").exists() and not (tmp_path / "registry.sqlite").exists()
    assert main(argv) == 0                                            # the file's own name is one
    text = (tmp_path / "cal.yaml").read_text().replace("\n  s:\n", "\n  ../x:\n")
    (tmp_path / "bad.yaml").write_text(text)
    with pytest.raises(ConfigError, match="is not an identifier"):
        load_calibration(tmp_path / "bad.yaml")
