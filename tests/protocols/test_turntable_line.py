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


@pytest.mark.parametrize(("overrides", "message"), [
    ({"move": {"send": ":demand:position {axis},{angle:.5f}"}}, r"move: ':demand:position' is not a SCPI header "
     "in the manuals' notation"),
    ({"setup": [{"send": ":Interlock:Close {axis}"}, {"send": "Mode:Position {axis}"}]},
     r"setup1: 'Mode:Position \{axis\}' does not start at the root"),
    ({"hold": {"send": ":Demand:Rate,{axis},0"}}, "hold: .*a blank, not a comma, ends the header"),
    ({"fault": {"send": ":INTerlock? {axis}", "reply": r"(?P<fault>\w+)", "answer": "{fault}"},
      "rotate": {"send": ":Demand:Rate {axis},{rate:.5f};Mode:Rate {axis}"}}, "rotate: .*does not start at the root"),
    ({"move_separator": "|"}, "move_separator: ACL joins commands in one line with ';'"),
])
def test_an_acl_template_the_controller_would_not_read_as_written_is_refused_naming_the_key(
        overrides: dict, message: str) -> None:
    with pytest.raises(ValidationError, match=message):
        turntable_protocol("acutrol3000", overrides)


@pytest.mark.parametrize(("request_text", "operation"), [
    (":D:P 3,10.5", "move"), (":Dem:Pos 3,10.50000", "move"), (":DEMAND:POSITION 3, 10.5", "move"),
    (":R:P? 2", "position"), (":read:pos 2", "position"), (":Read:Rate? 1", "rate"), (":INT? 1", "fault"),
    (":int:close 1", "setup0"), (":I:C 1", "setup0"), (":MODE:POS 3", "setup1"), (":M:P 2", "setup1"),
    (":L:R R,1,10.00000;:LIM:ACC R,1,5.00000;:D:R 1,-10.00000;:M:R 1", "rotate"),
])
def test_an_acl_profile_reads_every_documented_spelling(request_text: str, operation: str) -> None:
    commands = dict(ACUTROL3000.commands())
    assert ACUTROL3000.request_pattern(commands[operation]).fullmatch(request_text)


@pytest.mark.parametrize("request_text", [
    ":Demand:Posn 3,10.5", ":D:P,3,10.5", ":D:P3,10.5", ":L:A R,1,5.0", ":Demand:Position? 3", ":Read:Positions? 1",
    ":Mode:Position", ":INT:CLOSE ALL,1",
])
def test_an_acl_profile_reads_no_misspelling(request_text: str) -> None:
    assert not any(ACUTROL3000.request_pattern(command).fullmatch(request_text)
                   for _, command in ACUTROL3000.commands())


def test_a_field_named_twice_must_read_the_same_both_times() -> None:
    pattern = ACUTROL3000.request_pattern(ACUTROL3000.stop)
    assert pattern.fullmatch(":demand:rate 2,0;:mode:rate 2;:demand:rate 2,0")
    assert pattern.fullmatch(":demand:rate 2,0;:mode:rate 3;:demand:rate 2,0") is None


def test_status_commands_naming_an_axis_are_asked_per_axis() -> None:
    assert ACUTROL3000.fault.per_axis and ACUTROL3000.rate is not None and ACUTROL3000.rate.per_axis
    line = PROTOCOLS["accelcal-line"]
    assert line.move.per_axis and not line.fault.per_axis and line.busy is not None and not line.busy.per_axis
