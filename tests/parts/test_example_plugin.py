"""The example part plug-in (examples/accelcal-rig-icm42605), without installing it: its pyproject's entry point
names a `Part` named as the entry point and no built-in one, whose driver and simulated part load; registered
through a dist-info of the test's own, the registry finds it by name, and the example's rig config and procedure
(which name their schemas) pass `rig plan`. examples/ci-check.sh installs it and dry-runs the campaign."""

from __future__ import annotations

import re
import sys
import tomllib
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from accelcal_rig.cli import main
from accelcal_rig.config.schemas import shipped
from accelcal_rig.parts import registry
from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.part import Part
from accelcal_rig.plugins import load_object
from tests.config.test_schemas import as_an_editor_reads, validator
from tests.conftest import REPO

EXAMPLE = REPO / "examples" / "accelcal-rig-icm42605"
PROJECT = tomllib.loads((EXAMPLE / "pyproject.toml").read_text(encoding="utf-8"))["project"]
ENTRY_POINTS: dict[str, str] = PROJECT["entry-points"][registry.ENTRY_POINT_GROUP]


@pytest.fixture
def example_on_path(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The example's source importable; its module forgotten afterwards."""
    monkeypatch.syspath_prepend(str(EXAMPLE))
    yield
    for module in [m for m in sys.modules if m.split(".")[0] == "accelcal_rig_icm42605"]:
        del sys.modules[module]


@pytest.fixture
def registered(example_on_path: None, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The example's entry points as an installed distribution declares them (a dist-info on sys.path)."""
    dist_info = tmp_path / f"{PROJECT['name'].replace('-', '_')}-{PROJECT['version']}.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {PROJECT['name']}\n"
                                        f"Version: {PROJECT['version']}\n")
    (dist_info / "entry_points.txt").write_text(f"[{registry.ENTRY_POINT_GROUP}]\n" + "".join(
        f"{name} = {value}\n" for name, value in ENTRY_POINTS.items()))
    monkeypatch.syspath_prepend(str(tmp_path))
    registry.known_parts.cache_clear()
    yield
    registry.known_parts.cache_clear()


def test_the_entry_point_names_a_part_of_its_name_no_built_in_one(example_on_path: None) -> None:
    assert list(ENTRY_POINTS) == ["icm42605"]
    for name, reference in ENTRY_POINTS.items():
        found = load_object(reference, f"part plug-in {name!r}")
        assert isinstance(found, Part) and found.name == name
        # No built-in part has its name (one would win): unknown here, or this very part where it is installed.
        assert registry.known_parts().get(name, found) == found
        assert found.identity != ICM42688P.identity                 # told apart from its sibling by WHO_AM_I
        for channel in found.channels:                               # every range has its register code
            assert set(channel.range_codes) == set(channel.lsb_per_unit)
        assert len(found.odr_codes or ()) == len(found.output_data_rates_hz)
        # The driver that speaks it and the dry run's simulated part: the built-in ones, loaded by reference.
        assert callable(load_object(found.device, "device")) and callable(load_object(found.simulator, "simulator"))


def test_the_registry_finds_it_and_the_example_plans(registered: None, capsys: pytest.CaptureFixture[str]) -> None:
    assert registry.part("icm42605").label == "ICM-42605"
    assert main(["plan", str(EXAMPLE / "quick-icm42605.yaml")]) == 0
    assert "estimated duration" in capsys.readouterr().out


@pytest.mark.parametrize(("kind", "name"), [("rig-config", "sim-icm42605.yaml"), ("procedure", "quick-icm42605.yaml")])
def test_the_example_files_name_their_schema_and_validate(kind: str, name: str) -> None:
    path = EXAMPLE / name
    text = path.read_text(encoding="utf-8")
    named = re.fullmatch(r"# yaml-language-server: \$schema=(\S+)", text.splitlines()[0])
    assert named is not None and (path.parent / named.group(1)).resolve() == shipped(kind)
    assert list(validator(kind).iter_errors(as_an_editor_reads(yaml.safe_load(text)))) == []
    if kind == "rig-config":
        assert {s["part"] for s in yaml.safe_load(text)["fixture"]["sensors"]} == set(ENTRY_POINTS)


def test_a_plug_in_named_like_a_built_in_part_is_said_and_not_used(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                  caplog: pytest.LogCaptureFixture) -> None:
    dist_info = tmp_path / "shadowing-0.1.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text("Metadata-Version: 2.1\nName: shadowing\nVersion: 0.1\n")
    (dist_info / "entry_points.txt").write_text(f"[{registry.ENTRY_POINT_GROUP}]\nadxl355 = nowhere:PART\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry.known_parts.cache_clear()
    try:
        assert registry.part("adxl355").label == "ADXL355"          # the built-in, and no attempt to load nowhere
        assert "part plug-in 'adxl355' (nowhere:PART) is not used: a built-in part has that name" in caplog.text
    finally:
        registry.known_parts.cache_clear()
