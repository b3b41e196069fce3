"""Numbers in procedures and rig configs are YAML numbers only: text where a number belongs (`"2_0"`, `"1e3"`,
which pydantic alone reads as 20 and 1000), a boolean, or a float where a whole number belongs (`200.5`,
`200.0`) is refused in one line naming the file, the line and the key (docs/procedures.md, "Numbers")."""

from __future__ import annotations

import types
import typing
from collections.abc import Iterator
from pathlib import Path

import pytest
from pydantic import BaseModel
from pydantic.functional_validators import BeforeValidator

from accelcal_rig.config.bounds import real_number, whole_number
from accelcal_rig.config.load import load_procedure, load_rig, with_faults
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.errors import ConfigError
from tests.conftest import REPO, TINY_PROCEDURE

YAML_NUMBER = ": write it as a YAML number, without quotes or underscores \\(e.g. 20, -40.5, 1e3\\)$"


def numeric_leaves(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, object, list[object]]]:
    """(dotted key, int or float or Literal, validators) of every number a model reads, `[]` marking items."""
    for name, field in model.model_fields.items():
        yield from _leaf(prefix + name, field.annotation, list(field.metadata))


def _leaf(key: str, annotation: object, metadata: list[object]) -> Iterator[tuple[str, object, list[object]]]:
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        yield from _leaf(key, args[0], metadata + list(args[1:]))
    elif isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield from numeric_leaves(annotation, key + ".")
    elif annotation in (int, float) or (origin is typing.Literal and all(type(a) is int for a in args)):
        yield key, annotation, [m.func for m in metadata if isinstance(m, BeforeValidator)]
    elif origin in (typing.Union, types.UnionType):
        for member in args:
            if member is not type(None):
                yield from _leaf(key, member, metadata)
    elif origin in (list, tuple):
        for member in dict.fromkeys(a for a in args if a is not Ellipsis):
            yield from _leaf(key + "[]", member, [])


@pytest.mark.parametrize("model", [Procedure, RigConfig])
def test_every_number_of_the_models_refuses_text_and_every_whole_one_floats(model: type[BaseModel]) -> None:
    leaves = list(numeric_leaves(model))
    assert len(leaves) > 40
    wrong = [key for key, kind, checks in leaves if (whole_number if kind is not float else real_number) not in checks]
    assert not wrong, f"numbers read without the file's number check: {wrong}"


@pytest.mark.parametrize(("replace", "by", "expected"), [
    ("samples_per_pose: 20", 'samples_per_pose: "2_0"',
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got the text '2_0'" + YAML_NUMBER),
    ("samples_per_pose: 20", "samples_per_pose: 2_0",  # YAML 1.1 would read 20: a person's file reads YAML 1.2
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got the text '2_0'" + YAML_NUMBER),
    ("timeout_min: 120", 'timeout_min: "1e3"',
     r"tiny.yaml:4: soak.timeout_min: expected a number, got the text '1e3'" + YAML_NUMBER),
    ("samples_per_pose: 20", "samples_per_pose: 200.5",
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got 200.5$"),
    ("samples_per_pose: 20", "samples_per_pose: 200.0",
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got 200.0 \(write 200\)$"),
    ("samples_per_pose: 20", "samples_per_pose: 2e2",
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got 200.0 \(write 200\)$"),
    ("samples_per_pose: 20", "samples_per_pose: true",
     r"tiny.yaml:6: acquisition.samples_per_pose: expected a whole number, got true$"),
    ("odr_hz: 125", "odr_hz: yes", r"tiny.yaml:6: acquisition.odr_hz: expected a number, got true$"),
    ("setpoints_c: [30]", 'setpoints_c: [30, "40"]',
     r"tiny.yaml:3: setpoints_c\[1\]: expected a number, got the text '40'" + YAML_NUMBER),
    ("setpoints_c: [30]", "setpoints_c: [30, 1:30]", r"tiny.yaml:3: setpoints_c\[1\]: expected a number, got the "
                                                     r"text '1:30'$"),
    ("setpoints_c: [30]", 'setpoints_c: {from_c: "20", to_c: 40, step_c: 10}',
     r"tiny.yaml:3: setpoints_c: from_c, to_c and step_c must be numbers, written without quotes$"),
    ("timeout_min: 120", "timeout_min: 1e400", r"tiny.yaml:4: soak.timeout_min: Input should be a finite number$"),
])
def test_a_number_that_is_not_one_is_refused_naming_file_line_and_key(write, replace: str, by: str,
                                                                      expected: str) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace(replace, by))
    with pytest.raises(ConfigError, match=expected):
        load_procedure(path)


def test_numbers_as_an_engineer_writes_them_are_read_as_meant(write) -> None:
    text = (TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [-040, -020, 000, 020, 1.0e1]")
            .replace("timeout_min: 120", "timeout_min: 1.2e2").replace("odr_hz: 125", "odr_hz: 1.25e2"))
    procedure = load_procedure(write("tiny.yaml", text)).model
    assert procedure.setpoints_c == [-40.0, -20.0, 0.0, 20.0, 10.0]  # YAML 1.1: -32, -16, 0, 16 and the text '1.0e1'
    assert procedure.soak.timeout_min == 120.0 and procedure.acquisition.odr_hz == 125.0


@pytest.mark.parametrize(("replace", "by", "expected"), [
    ("max_setpoint_c: 100", 'max_setpoint_c: "100"',
     r"rig.yaml:LINE: chamber.max_setpoint_c: expected a number, got the text '100'" + YAML_NUMBER),
    ("chamber:\n", "chamber:\n  device_id: 1.0\n",
     r"rig.yaml:\d+: chamber.device_id: expected a whole number, got 1.0 \(write 1\)$"),
    ("chamber:\n", "chamber:\n  stopbits: 2.0\n", r"rig.yaml:\d+: chamber.stopbits: expected a whole number, got 2.0"),
    ("chamber:\n", 'chamber:\n  timeout_s: "1"\n',
     r"rig.yaml:\d+: chamber.timeout_s: expected a number, got the text '1'" + YAML_NUMBER),
    ("axis: [0, 0, 1]", 'axis: [0, 0, "1"]',
     r"rig.yaml:LINE: turntable.axes\[0\].axis\[2\]: expected a number, got the text '1'" + YAML_NUMBER),
])
def test_a_rig_config_number_that_is_not_one_is_refused_naming_file_line_and_key(tmp_path: Path, replace: str,
                                                                                 by: str, expected: str) -> None:
    text = (REPO / "configs" / "sim.yaml").read_text()
    assert replace in text
    path = tmp_path / "rig.yaml"
    path.write_text(text.replace(replace, by, 1))
    line = text[:text.index(replace)].count("\n") + 1      # the line the wrong value is on
    with pytest.raises(ConfigError, match=expected.replace("LINE", str(line))):
        load_rig(path)


def test_the_command_lines_fault_settings_are_text_and_read_as_numbers() -> None:
    rig = with_faults(load_rig(REPO / "configs" / "sim.yaml"), "rate=0.05,seed=3,delay_s=1e-2,kinds=drop+delay")
    faults = rig.model.simulation.faults
    assert (faults.rate, faults.seed, faults.delay_s, faults.kinds) == (0.05, 3, 0.01, ["drop", "delay"])
    with pytest.raises(ConfigError, match=r"--faults: rate: Input should be less than or equal to 1"):
        with_faults(load_rig(REPO / "configs" / "sim.yaml"), "rate=2")


@pytest.mark.parametrize("path", sorted((REPO / "configs").glob("*.yaml")), ids=lambda p: p.name)
def test_every_shipped_rig_config_loads(path: Path) -> None:
    assert load_rig(path).model.name
