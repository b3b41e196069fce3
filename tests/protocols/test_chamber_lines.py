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
