from pathlib import Path

import pytest

from accelcal_rig.config.yaml_lines import format_key, load_yaml_with_lines, locate
from accelcal_rig.errors import ConfigError


def test_lines_of_nested_keys_and_list_items(tmp_path: Path) -> None:
    path = tmp_path / "a.yaml"
    path.write_text("a: 1\nb:\n  c: 2\n  d:\n    - 3\n    - 4\n")
    data, lines, _ = load_yaml_with_lines(path)
    assert data == {"a": 1, "b": {"c": 2, "d": [3, 4]}}
    assert lines[("a",)] == 1
    assert lines[("b", "c")] == 3
    assert lines[("b", "d", 1)] == 6


def test_duplicate_key_is_an_error_with_its_line(tmp_path: Path) -> None:
    path = tmp_path / "dup.yaml"
    path.write_text("a: 1\nb: 2\na: 3\n")
    with pytest.raises(ConfigError, match=r"dup.yaml:3: a: duplicate key"):
        load_yaml_with_lines(path)


def test_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("a: 1\nb: [1, 2\nc: 3\n")
    with pytest.raises(ConfigError, match=r"bad.yaml:\d+: syntax: "):
        load_yaml_with_lines(path)


@pytest.mark.parametrize("text", ["", "- 1\n- 2\n", "just a string\n"])
def test_top_level_must_be_a_mapping(tmp_path: Path, text: str) -> None:
    path = tmp_path / "x.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"x.yaml:1: "):
        load_yaml_with_lines(path)


def test_locate_skips_union_tags_and_names_missing_keys() -> None:
    lines = {(): 1, ("schedule",): 4, ("schedule", "kind"): 5}
    assert locate(lines, ("schedule", "sphere", "count")) == (("schedule", "count"), 4)
    assert format_key(("schedule", "angles_deg", 3)) == "schedule.angles_deg[3]"
