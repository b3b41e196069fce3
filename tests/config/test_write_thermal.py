"""Measured thermal constants written into a rig config: the `thermal:` block replaced or appended, every
other byte as the lab wrote it; a write that would break the config refused with the file unchanged."""

from __future__ import annotations

from pathlib import Path

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.write_thermal import write_thermal
from accelcal_rig.errors import ConfigError
from tests.conftest import SIM_RIG

#: The simulated rig's config as a rig never characterised has it (without its own thermal: block).
UNMEASURED = SIM_RIG.read_text().split("\n# The rig's own thermal constants")[0]
MEASURED = {"heating_rate_c_per_min": 2.75, "cooling_rate_c_per_min": 1.5, "cooling_floor_c": -80.0, "room_c": 22.5,
            "chamber_time_constant_min": 3.25, "chamber_overshoot_pct": 1.5, "fixture_time_constant_min": 12.0}


def test_the_section_is_appended_then_replaced_and_nothing_else_changes(tmp_path: Path) -> None:
    config = tmp_path / "lab.yaml"
    original = UNMEASURED + "thermal:  # measured last spring\n  heating_rate_c_per_min: 9\n\n# the end\n"
    config.write_text(original)
    write_thermal(config, MEASURED, "rig characterise a.h5 on 2026-12-02")
    text = config.read_text()
    assert text.startswith(UNMEASURED) and text.endswith("\n\n# the end\n")  # the comment after it kept
    thermal = load_rig(config).model.thermal
    assert (thermal.heating_rate_c_per_min, thermal.cooling_floor_c, thermal.measured) == (
        2.75, -80.0, "rig characterise a.h5 on 2026-12-02")
    write_thermal(config, {**MEASURED, "cooling_floor_c": None}, "again")  # a floor not seen: its key goes
    assert load_rig(config).model.thermal.cooling_floor_c is None and config.read_text().count("thermal:") == 1


def test_a_write_that_would_break_the_config_is_refused_and_the_file_left_as_it_was(tmp_path: Path) -> None:
    config = tmp_path / "lab.yaml"
    config.write_text(UNMEASURED)
    with pytest.raises(ConfigError, match=r"thermal.cooling_floor_c: -50 °C is not below the chamber's lowest set "
                                          r"point .* was left as it was"):
        write_thermal(config, {**MEASURED, "cooling_floor_c": -50.0}, "x")  # the rig's chamber goes to -55 °C
    assert config.read_text() == UNMEASURED
    config.write_text(UNMEASURED + "thermal: {heating_rate_c_per_min: 2}\n")  # flow style: not ours to edit
    with pytest.raises(ConfigError, match="its thermal: is not a block of its own lines"):
        write_thermal(config, MEASURED, "x")
    assert config.read_text().endswith("thermal: {heating_rate_c_per_min: 2}\n")


def test_a_linked_config_is_written_where_the_link_points_and_stays_a_link(tmp_path: Path) -> None:
    real = tmp_path / "configs" / "lab.yaml"
    real.parent.mkdir()
    real.write_text(UNMEASURED)
    link = tmp_path / "rig.yaml"
    link.symlink_to(real)
    write_thermal(link, MEASURED, "rig characterise a.h5")
    assert link.is_symlink() and load_rig(real).model.thermal.heating_rate_c_per_min == 2.75


def test_line_endings_and_the_sections_own_comments_are_kept(tmp_path: Path) -> None:
    config = tmp_path / "lab.yaml"
    section = ("thermal:  # the chamber's, not the data sheet's\n"
               "  # measured after the door seal was replaced\n"
               "  heating_rate_c_per_min: 9   # from a 60 °C step\n"
               "  room_c: 21\n")
    original = (UNMEASURED + section + "\n# the end\n").replace("\n", "\r\n")
    config.write_bytes(original.encode())
    write_thermal(config, MEASURED, "rig characterise a.h5")
    written = config.read_bytes().decode()
    assert "\n" not in written.replace("\r\n", "")                          # every line still CRLF
    assert written.startswith(UNMEASURED.replace("\n", "\r\n")) and written.endswith("\r\n\r\n# the end\r\n")
    assert ("thermal:  # the chamber's, not the data sheet's\r\n  # measured after the door seal was replaced\r\n"
            "  heating_rate_c_per_min: 2.75   # from a 60 °C step\r\n") in written
    assert load_rig(config).model.thermal.room_c == 22.5
