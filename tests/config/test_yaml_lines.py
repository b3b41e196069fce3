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


@pytest.mark.parametrize(("written", "read"), [
    ("20", 20), ("-40.5", -40.5), ("+5", 5), ("1.", 1.0), ("0.001", 0.001),
    ("1e3", 1000.0), ("1.0e3", 1000.0), ("1E3", 1000.0), ("-2.5e6", -2.5e6), ("1.5e-3", 0.0015), ("1.0e+3", 1000.0),
    ("6.02e23", 6.02e23), (".5e2", 50.0),                   # YAML 1.1 (PyYAML): text
    ("010", 10), ("-040", -40), ("000", 0),                 # YAML 1.1: octal 8, -32
    ("0x1F", 31), ("0o17", 15),
    ("2_0", "2_0"), ("1_000.5", "1_000.5"), ("1:30", "1:30"), ("0b101", "0b101"),  # YAML 1.1: 20, 1000.5, 90, 5
    ("'1e3'", "1e3"), ('"20"', "20"), ("1e", "1e"), ("12E3x", "12E3x"),
    ("true", True), ("2025-01-02", "2025-01-02"),
])
def test_a_persons_numbers_are_read_as_yaml_1_2_reads_them(tmp_path: Path, written: str, read: object) -> None:
    path = tmp_path / "n.yaml"
    path.write_text(f"k: {written}\nlist: [{written}]\n")
    data, _, _ = load_yaml_with_lines(path)
    assert data["k"] == read and type(data["k"]) is type(read)
    assert data["list"] == [read]


def test_infinities_and_nans_are_still_read_for_the_models_to_refuse_by_name(tmp_path: Path) -> None:
    path = tmp_path / "n.yaml"
    path.write_text("a: .inf\nb: -.inf\nc: .nan\nd: 1e400\n")
    data, _, _ = load_yaml_with_lines(path)
    assert data["a"] == data["d"] == float("inf") and data["b"] == float("-inf") and data["c"] != data["c"]


def test_only_a_persons_files_read_yaml_1_2_numbers() -> None:
    import yaml

    assert yaml.safe_load("k: 1e3")["k"] == "1e3" and yaml.safe_load("k: 010")["k"] == 8  # PyYAML's own, untouched
