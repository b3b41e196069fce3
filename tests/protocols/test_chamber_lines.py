"""Chamber line-protocol profiles are data: every built-in one is valid, and a broken override says what
is wrong with it."""

from __future__ import annotations

from typing import get_args

import pytest
from pydantic import ValidationError

from accelcal_rig.config.rig import ChamberConfig, ChamberProfile
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, OPERATIONS, line_protocol
from accelcal_rig.protocols.chamber_registers import PROFILES


def test_the_config_knows_every_built_in_profile_and_no_other() -> None:
    assert set(get_args(ChamberProfile)) == {*PROFILES, *LINE_PROFILES}
    assert not set(PROFILES) & set(LINE_PROFILES)


@pytest.mark.parametrize("profile", sorted(LINE_PROFILES))
def test_each_profile_answers_its_own_requests(profile: str) -> None:
    """The simulator recognises a request by its command's template: every request a driver sends must match
    its own command's pattern (and the first such, so that it is answered as that operation)."""
    protocol = LINE_PROFILES[profile]
    patterns = protocol.request_patterns()
    for operation in OPERATIONS:
        command = protocol.command(operation)
        if command is None:
            continue
        request = command.send.format(value=-12.5)
        first = next(op for op, _, pattern in patterns if pattern.fullmatch(request))  # type: ignore[attr-defined]
        assert protocol.command(first).send == command.send


@pytest.mark.parametrize(("overrides", "message"), [
    ({"error_pattern": "(unclosed"}, "not a regular expression"),
    ({"identify": {"send": "ID? {axis}", "reply": "(?P<identity>.+)", "answer": "{identity}"}},
     "template fields axis unknown"),
    ({"read_temperature": {"send": "T?", "reply": "[0-9.]+", "answer": "1"}}, r"must capture \(pv\)"),
    ({"read_low_limit": None}, "read_low_limit and read_high_limit come together"),
    ({"identify": {"send": "ID¶", "reply": "(?P<identity>.+)", "answer": "{identity}"}}, "not ascii text"),
    ({"write_setpoint": {"send": "S {value}", "reply": "OK"}}, "both a reply pattern and an answer, or neither"),
    ({"write_setpoint": {"send": "TEMP, S25.0", "reply": "OK:.*", "answer": "OK:"}}, "must name the set point once"),
    ({"write_setpoint": {"send": "TEMP, S{value:.0f}0", "reply": "OK:.*", "answer": "OK:"}},
     "must not run into digits or signs"),
    ({"identify": {"send": "TYPE? {pv}", "reply": "(?P<identity>.+)", "answer": "{identity}"}},
     "template fields pv unknown"),
    ({"alarm": {"send": "TEMP?", "reply": "(?P<alarm>.+)", "answer": "{alarm}"}}, None),
    ({"humidity": {"send": "TEMP? ", "reply": "(?P<humidity>.+)", "answer": "{humidity}"}}, "blanks at either end"),
])
def test_a_broken_override_names_its_problem(overrides: dict, message: str | None) -> None:
    if message is None:  # the same command as another operation's (ESPEC's TEMP? carries four values): allowed
        line_protocol("espec-p300", overrides)
        return
    with pytest.raises(ValidationError, match=message):
        line_protocol("espec-p300", overrides)


def test_one_requests_text_must_not_read_as_anothers() -> None:
    """`S 1` to run would be taken for a set point of 1 °C (by the simulator, and by anyone reading a log)."""
    with pytest.raises(ValidationError, match="power_on: its request 'S 1' reads as write_setpoint's"):
        line_protocol("thermotron-8800", {"write_setpoint": {"send": "S {value:.1f}", "reply": "0", "answer": "0"},
                                          "power_on": {"send": "S 1", "reply": "0", "answer": "0"}})


def test_a_rig_config_pairs_line_profiles_with_the_line_driver() -> None:
    assert ChamberConfig(driver="line", profile="simserv", endpoint="10.0.0.5:2049").line_protocol().default_port == 2049
    with pytest.raises(ValidationError, match="profile simserv is a line protocol: use driver: line"):
        ChamberConfig(driver="modbus-tcp", profile="simserv")
    with pytest.raises(ValidationError, match="profile watlow-f4 is a Modbus register map"):
        ChamberConfig(driver="line", profile="watlow-f4")
    with pytest.raises(ValidationError, match=r"protocol_overrides\.units_celsius"):
        ChamberConfig(driver="line", profile="thermotron-8800", protocol_overrides={"units_celsius": "x" * 40})


@pytest.mark.parametrize(("profile", "overrides", "message"), [
    ("watlow-f4t-scpi", {"write_setpoint": {"send": ":source:cloop1:spoint {value}"}},
     r"write_setpoint: ':source:cloop1:spoint' is not a SCPI header in the manuals' notation"),
    ("watlow-f4t-scpi", {"units": {"send": ":UNIT:TEMP_C?", "reply": "(?P<units>C)", "answer": "C"}},
     r"units: ':UNIT:TEMP_C\?' is not a SCPI header"),
    ("simserv", {"identify": {"send": "99997\u00b61", "reply": "1\u00b6(?P<identity>.*)", "answer": "1\u00b6x"}},
     r"identify: '99997¶1': SIMSERV command 99997 takes 2 fields after its number .* not 1 \(the controller "
     r"answers -6\)"),
    ("simserv", {"alarm": {"send": "10013\u00b61", "reply": "1\u00b6(?P<alarm>\\d+)", "answer": "1\u00b61"}},
     r"alarm: '10013¶1': SIMSERV has no command '10013'"),
])
def test_a_request_the_controller_family_cannot_read_is_refused_naming_the_operation(
        profile: str, overrides: dict, message: str) -> None:
    with pytest.raises(ValidationError, match=message):
        line_protocol(profile, overrides)


def test_scpi_templates_are_sent_as_upper_case_long_forms_and_read_in_any_spelling() -> None:
    protocol = line_protocol("watlow-f4t-scpi")
    assert protocol.request("write_setpoint", value=30.0) == ":SOURCE:CLOOP1:SPOINT 30.00"
    patterns = {operation: pattern for operation, _, pattern in protocol.request_patterns()}
    for spelling in (":SOURCE:CLOOP1:SPOINT 30", "SOURCE:CLOOP1:SPOINT 30", ":sour:clo1:spo 30", "sour:clo:spo 30",
                     ":SOURce:CLOop1:SPOint   3.0E+01"):
        assert patterns["write_setpoint"].fullmatch(spelling), spelling  # type: ignore[attr-defined]
    for other in (":SOURCE:CLOOP2:SPOINT 30", ":SOURC:CLOOP1:SPOINT 30", ":SOURCE:CLOOP1:SPOINT"):
        assert not patterns["write_setpoint"].fullmatch(other), other  # type: ignore[attr-defined]


def test_espec_requests_are_read_with_or_without_a_blank_after_each_comma() -> None:
    patterns = {operation: pattern for operation, _, pattern in LINE_PROFILES["espec-p300"].request_patterns()}
    for spelling in ("MODE,CONSTANT", "MODE, CONSTANT"):
        assert patterns["power_on"].fullmatch(spelling)  # type: ignore[attr-defined]
    for spelling in ("TEMP,S31.0", "TEMP, S31.0"):
        assert patterns["write_setpoint"].fullmatch(spelling)["value"] == "31.0"  # type: ignore[attr-defined]
    assert not patterns["power_on"].fullmatch("MODE,  CONSTANT")  # type: ignore[attr-defined]
