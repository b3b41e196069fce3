"""The JSON Schemas editors check procedures and rig configs with (config/schemas.py): the shipped ones are the
models' own (a model change without `rig schema KIND -o schemas/…` fails here), every shipped file
names its schema in its first line and validates against it, and a misspelled key or a value out of bounds is
refused by the schema as by `rig` itself."""

from __future__ import annotations

import datetime as dt
import json
import re
from typing import Any

import jsonschema
import pytest
import yaml

from accelcal_rig.cli import main
from accelcal_rig.config.schemas import KINDS, schema_text, shipped
from tests.conftest import REPO, TINY_PROCEDURE

FOLDERS = {"procedure": REPO / "procedures", "rig-config": REPO / "configs"}


def as_an_editor_reads(value: Any) -> Any:
    """YAML as the language server reads it (YAML 1.2's core schema: a date is text)."""
    if isinstance(value, dict):
        return {str(k): as_an_editor_reads(v) for k, v in value.items()}
    if isinstance(value, list):
        return [as_an_editor_reads(v) for v in value]
    return value.isoformat() if isinstance(value, dt.date) else value


def validator(kind: str) -> jsonschema.Draft202012Validator:
    found = json.loads(shipped(kind).read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(found)
    return jsonschema.Draft202012Validator(found)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_the_shipped_schema_is_the_models(kind: str) -> None:
    assert shipped(kind).read_text(encoding="utf-8") == schema_text(kind), (
        f"{shipped(kind)} is not the models' schema: rig schema {kind} -o {shipped(kind).relative_to(REPO)}")


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_shipped_file_names_its_schema_and_validates(kind: str) -> None:
    files = sorted(FOLDERS[kind].glob("*.yaml"))
    assert files
    check = validator(kind)
    for path in files:
        first = path.read_text(encoding="utf-8").splitlines()[0]
        named = re.fullmatch(r"# yaml-language-server: \$schema=(\S+)", first)
        assert named is not None, f"{path}: its first line does not name its schema"
        assert (path.parent / named.group(1)).resolve() == shipped(kind)
        errors = [f"{list(e.absolute_path)}: {e.message}" for e in check.iter_errors(
            as_an_editor_reads(yaml.safe_load(path.read_text(encoding="utf-8"))))]
        assert errors == [], f"{path}: {errors[:3]}"


@pytest.mark.parametrize(("kind", "text", "wrong", "key"), [
    ("procedure", TINY_PROCEDURE.replace("samples_per_pose:", "samples_per_pos:"), "samples_per_pos", "samples_per_pos"),
    ("procedure", TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [400]"), "400", "setpoints_c"),
    ("rig-config", (REPO / "configs" / "sim.yaml").read_text().replace("fixture:", "fixtures:", 1), "fixtures",
     "fixtures"),
])
def test_a_misspelled_key_or_a_value_out_of_bounds_is_refused_by_both(kind: str, text: str, wrong: str, key: str,
                                                                         write, capsys) -> None:
    errors = list(validator(kind).iter_errors(as_an_editor_reads(yaml.safe_load(text))))
    assert errors and any(wrong in e.message for e in errors), [e.message for e in errors]
    if kind == "procedure":
        assert main(["plan", str(write("tiny.yaml", text))]) == 2              # rig refuses it too
    else:
        assert main(["plan", str(write("tiny.yaml", TINY_PROCEDURE)), "--config", str(write("rig.yaml", text))]) == 2
    assert key in capsys.readouterr().err


def test_rig_schema_prints_what_the_package_ships(capsys) -> None:
    assert main(["schema", "procedure"]) == 0
    assert capsys.readouterr().out == shipped("procedure").read_text(encoding="utf-8")
