"""Turntable line-protocol profiles are data: built-in ones are valid, a profile must be able to tell a move
is complete, and a template read back as a pattern recognises exactly its own requests."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from accelcal_rig.protocols.turntable_line import ACUTROL3000, PROTOCOLS, turntable_protocol


@pytest.mark.parametrize(("overrides", "message"), [
    ({"busy": None, "rate": None, "rotate": None, "hold": None}, "needs a busy query or a rate query"),
    ({"fault": {"send": "F?", "reply": "[0-9]+", "answer": "0"}}, r"fault: the reply pattern must capture \(fault\)"),
    ({"multi_axis_move": True, "move": {"send": "MOVEALL {angle}", "reply": "OK", "answer": "OK"}},
     "the move must name {axis}"),
    ({"stop": {"send": "STOP {speed}", "reply": "OK", "answer": "OK"}}, "template fields speed unknown"),
    ({"stop": {"send": "STOP", "reply": "OK"}}, "both a reply pattern and an answer, or neither"),
    ({"stop": {"send": "STOP {busy}", "reply": "OK", "answer": "OK"}}, "template fields busy unknown"),
    ({"move": {"send": "MOV {axis} {angle:>12.5f}", "reply": "OK", "answer": "OK"}}, "does not read back as itself"),
    ({"multi_axis_move": True}, "the move must be unanswered"),
])
def test_a_broken_profile_names_its_problem(overrides: dict, message: str) -> None:
    with pytest.raises(ValidationError, match=message):
        turntable_protocol("accelcal-line", overrides)


def test_a_field_named_twice_must_read_the_same_both_times() -> None:
    pattern = ACUTROL3000.stop.request_pattern()
    assert pattern.fullmatch(":demand:rate 2,0;:mode:rate 2;:demand:rate 2,0")
    assert pattern.fullmatch(":demand:rate 2,0;:mode:rate 3;:demand:rate 2,0") is None


def test_status_commands_naming_an_axis_are_asked_per_axis() -> None:
    assert ACUTROL3000.fault.per_axis and ACUTROL3000.rate is not None and ACUTROL3000.rate.per_axis
    line = PROTOCOLS["accelcal-line"]
    assert line.move.per_axis and not line.fault.per_axis and line.busy is not None and not line.busy.per_axis
