"""rig init: the starting set a lab edits, written whole into a new or empty folder, never over a user's files,
and usable where it lands (a procedure's rig: and each file's schema line hold in the folder written)."""

from __future__ import annotations

import re

import pytest

from accelcal_rig.cli.commands import main
from accelcal_rig.config.schemas import KINDS, shipped
from accelcal_rig.config.starter import FOLDERS, starter_files, write_starter
from accelcal_rig.errors import ConfigError
from tests.conftest import REPO


def test_the_starting_set_is_every_shipped_procedure_config_and_schema() -> None:
    named = {str(path) for path in starter_files()}
    for folder in FOLDERS:
        assert {f"{folder}/{p.name}" for p in (REPO / folder).iterdir() if p.suffix in (".yaml", ".json")} <= named
    assert "README.md" in named


def test_rig_init_writes_a_folder_whose_procedures_plan(tmp_path, monkeypatch, capsys) -> None:
    lab = tmp_path / "lab"
    assert main(["init", str(lab)]) == 0
    assert f"into {lab}" in capsys.readouterr().out
    for relative in starter_files():
        assert (lab / relative).read_bytes() == (REPO / "accelcal_rig" / "starter" / relative).read_bytes()
    for kind, folder in (("procedure", "procedures"), ("rig-config", "configs")):
        for path in (lab / folder).glob("*.yaml"):
            named = re.fullmatch(r"# yaml-language-server: \$schema=(\S+)", path.read_text().splitlines()[0])
            assert named and (path.parent / named.group(1)).read_bytes() == shipped(kind).read_bytes(), path
    assert sorted(KINDS) == ["procedure", "rig-config"]
    monkeypatch.chdir(lab)
    assert main(["plan", "procedures/quick-6pos.yaml"]) == 0      # its rig: ../configs/sim.yaml found there
    assert "estimated duration" in capsys.readouterr().out


def test_an_empty_folder_is_written_and_nothing_of_a_users_is_replaced(tmp_path, capsys) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    assert len(write_starter(empty)) == len(starter_files())
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("my notes")
    assert main(["init", str(mine)]) == 2
    assert f"{mine} is not empty; nothing written" in capsys.readouterr().err
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]
    with pytest.raises(ConfigError, match="does not exist"):
        write_starter(tmp_path / "no" / "such" / "lab")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "mine"]   # no half-written staging left


def test_a_folder_that_cannot_be_written_is_one_line(tmp_path, monkeypatch, capsys) -> None:
    def refused(**_: object) -> str:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("accelcal_rig.config.starter.tempfile.mkdtemp", refused)
    assert main(["init", str(tmp_path / "lab")]) == 2
    assert capsys.readouterr().err.strip() == f"rig: error: cannot write {tmp_path / 'lab'}: Permission denied"
    assert not (tmp_path / "lab").exists()
