"""A chamber driver from outside the repository: a tiny package, built and installed into the test's own
folder, registers it through the `accelcal_rig.chambers` entry point, with its simulator; `rig check
--dry-run` then finds it by the rig config's `driver:` and talks to it over its own wire."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO, SIM_RIG
from tests.test_check_and_sim import check_lines

RIG = str(Path(sys.executable).parent / "rig")
PACKAGE = REPO / "tests" / "plugins_acme"


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The acme-chamber package built from its source and installed into a folder of its own."""
    folder = tmp_path_factory.mktemp("plugin")
    source, site = folder / "acme", folder / "site"
    shutil.copytree(PACKAGE, source)
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(site), str(source)],
                   check=True, capture_output=True, timeout=300)
    return site


def acme_rig(folder: Path) -> Path:
    path = folder / "acme-rig.yaml"
    path.write_text(SIM_RIG.read_text().replace("driver: modbus-tcp", "driver: acme-ascii", 1))
    return path


def test_rig_check_finds_an_installed_chamber_driver_and_its_simulator(installed: Path, tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(installed)}
    result = subprocess.run([RIG, "check", str(acme_rig(tmp_path)), "--dry-run"], capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    status, chamber = check_lines(result.stdout)["chamber"]
    assert status == "OK" and chamber.startswith("acme 127.0.0.1:")
    assert (": ACME TC-1 (PV 23.0 °C), alarm clear; set point limits: the rig's -55…100 °C, the controller exposes "
            "none") in chamber
    assert "every instrument answered as configured" in result.stdout


def test_without_the_package_the_driver_is_unknown_in_one_line(tmp_path: Path) -> None:
    result = subprocess.run([RIG, "check", str(acme_rig(tmp_path)), "--dry-run"], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 2
    assert result.stderr.strip().endswith("chamber.driver: unknown chamber driver 'acme-ascii' (known: line, "
                                          "modbus-rtu, modbus-tcp)")
