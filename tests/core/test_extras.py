"""Every hint the program prints to install an optional capability names an extra the package declares, with
the packages it stands for as the installed metadata has them (pip can install both)."""

from __future__ import annotations

import re
from importlib.metadata import metadata

from accelcal_rig.core.extras import extra_packages, install_hint
from tests.conftest import REPO


def declared_extras() -> set[str]:
    return set(metadata("accelcal-rig").get_all("Provides-Extra") or [])


def test_every_hint_in_the_code_names_a_declared_extra() -> None:
    named = {extra for path in (REPO / "accelcal_rig").rglob("*.py")
             for extra in re.findall(r"install_hint\(['\"]([a-z-]+)['\"]\)", path.read_text(encoding="utf-8"))}
    assert {"dashboard", "pdf", "postgresql", "report", "spi"} <= named
    assert named <= declared_extras()
    written = {extra for path in [*(REPO / "accelcal_rig").rglob("*.py"), *(REPO / "docs").rglob("*.md")]
               for extra in re.findall(r"accelcal-rig\[([a-z,-]+)\]", path.read_text(encoding="utf-8"))}
    assert {e for group in written for e in group.split(",")} <= declared_extras()


def test_the_hint_names_the_extra_and_its_packages() -> None:
    assert any(p.startswith("starlette") for p in extra_packages("dashboard"))
    hint = install_hint("dashboard")
    assert hint.startswith("pip install 'accelcal-rig[dashboard]'") and "uvicorn" in hint
    assert extra_packages("no-such-extra") == []
    assert set(declared_extras()) >= {"dashboard", "pdf", "postgresql", "all"}
