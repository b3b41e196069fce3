"""The line chamber driver against exact request/reply bytes, in memory: each built-in profile as the
controller sees it, and every kind of bad reply as one line naming the chamber."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import ControllerLimits, controller_limits
from accelcal_rig.instruments.chamber_line import LineChamber
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, ChamberLineProtocol, line_protocol
from tests.instruments.expected_protocol import expected_protocol

Conversation = Sequence[tuple[bytes, bytes | None]]


def talk(profile: str | ChamberLineProtocol, conversation: Conversation):
    """A driver of `profile` whose wire is the conversation (checked byte for byte)."""
    protocol = LINE_PROFILES[profile] if isinstance(profile, str) else profile
    return expected_protocol(conversation, "chamber (memory)", protocol.write_terminator, protocol.read_terminator,
                             protocol.encoding), protocol


def test_espec_p300_reads_one_temp_reply_for_value_set_point_and_limits() -> None:
    """It sends ESPEC's library's spelling (`MODE,CONSTANT`, `TEMP, S<v>`) and reads `TEMP?` with or without
    a blank after each comma (py-lab-hal's PU-3J class splits on ", ")."""
    context, protocol = talk("espec-p300", [
        (b"TYPE?\r\n", b"DRY,P300,180\r\n"),
        (b"TEMP?\r\n", b"23.4,25.0,180.0,-70.0\r\n"), (b"TEMP?\r\n", b"23.4,25.0,180.0,-70.0\r\n"),
        (b"TEMP, S-40.0\r\n", b"OK:TEMP, S-40.0\r\n"),
        (b"TEMP?\r\n", b"23.1,-40.0,180.0,-70.0\r\n"), (b"TEMP?\r\n", b"23.1, -40.0, 180.0, -70.0\r\n"),
        (b"MODE,CONSTANT\r\n", b"OK:MODE,CONSTANT\r\n"), (b"MODE,STANDBY\r\n", b"OK:MODE,STANDBY\r\n"),
        (b"ALARM?\r\n", b"0\r\n"), (b"ALARM?\r\n", b"2,11,14\r\n"),
    ])
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        assert chamber.identify() == "DRY,P300,180 (PV 23.4 °C, SP 25.0 °C)"
        chamber.write_setpoint_c(-40.0)
        assert chamber.controller_limits_c() == (-70.0, 180.0)
        chamber.set_power(True)
        chamber.set_power(False)
        assert not chamber.alarm_active()
        assert chamber.alarm_active()


def test_thermotron_8800_checks_its_units_and_answers_operations_with_zero() -> None:
    context, protocol = talk("thermotron-8800", [
        (b"IDEN?\r", b"8800 v2.14\r\n"), (b"CCHR1?\r", b"C\r\n"),
        (b"PVAR1?\r", b"-39.87\r\n"), (b"SETP1?\r", b"-40.00\r\n"),
        (b"SETP1,85.0\r", b"0\r\n"), (b"RUNM\r", b"0\r\n"), (b"STOP\r", b"0\r\n"), (b"ALRM1?\r", b"0\r\n"),
    ])
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        assert chamber.identify() == "8800 v2.14 (PV -39.9 °C, SP -40.0 °C)"
        chamber.write_setpoint_c(85.0)
        chamber.set_power(True)
        chamber.set_power(False)
        assert not chamber.alarm_active()
        assert not isinstance(chamber, ControllerLimits)  # the 8800 profile exposes none
        assert controller_limits(chamber) is None


def test_simserv_numbered_commands_with_its_separator_byte() -> None:
    """`99997¶1¶1` asks for the test system type (basil, SengerM); fields after a value are taken; the alarm
    is bit 8 of the status (1 idle, +2 running, +4 warnings, +8 alarms)."""
    context, protocol = talk("simserv", [
        (b"99997\xb61\xb61\r", b"1\xb6LabEvent T/210/70/5\r\n"), (b"11023\xb61\xb61\r", b"1\xb6\xb0C\r\n"),
        (b"11004\xb61\xb61\r", b"1\xb622.9\xb6extra\r\n"), (b"11002\xb61\xb61\r", b"1\xb623.0\r\n"),
        (b"11001\xb61\xb61\xb6-40.0\r", b"1\r\n"),
        (b"11007\xb61\xb61\r", b"1\xb6-75.0\r\n"), (b"11009\xb61\xb61\r", b"1\xb6180.0\r\n"),
        (b"14001\xb61\xb61\xb61\r", b"1\r\n"), (b"10012\xb61\r", b"1\xb63\r\n"), (b"10012\xb61\r", b"1\xb611\r\n"),
        (b"10012\xb61\r", b"1\xb67\r\n"), (b"10012\xb61\r", b"1\xb68\r\n"),
        (b"14001\xb61\xb68\xb61\r", b"1\r\n"),
    ])
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        assert chamber.identify() == "LabEvent T/210/70/5 (PV 22.9 °C, SP 23.0 °C)"
        chamber.write_setpoint_c(-40.0)
        assert chamber.controller_limits_c() == (-75.0, 180.0)
        chamber.set_power(True)
        assert not chamber.alarm_active()  # 3: running
        assert chamber.alarm_active()  # 11 = 3 + 8: running with alarms
        assert not chamber.alarm_active()  # 7 = 3 + 4: running with warnings only
        assert chamber.alarm_active()  # 8: bit 8 alone (a status no client lists) is still an alarm
        chamber.set_purge(True)


def test_watlow_f4t_scpi_settings_are_sent_unanswered() -> None:
    context, protocol = talk("watlow-f4t-scpi", [
        (b"*IDN?\n", b"Watlow F4T 04.07.0012\n"), (b":UNIT:TEMPERATURE?\n", b"C\n"),
        (b":SOURCE:CLOOP1:PVALUE?\n", b"24.51\n"), (b":SOURCE:CLOOP1:SPOINT?\n", b"25.00\n"),
        (b":SOURCE:CLOOP1:SPOINT -12.50\n", None), (b":SOURCE:CLOOP2:PVALUE?\n", b"41.20\n"),
    ])
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        assert chamber.identify() == "Watlow F4T 04.07.0012 (PV 24.5 °C, SP 25.0 °C)"
        chamber.write_setpoint_c(-12.5)
        assert chamber.read_humidity_pct() == pytest.approx(41.2)
        with pytest.raises(InstrumentError, match=r"chamber \(memory\): the protocol profile has no power command"):
            chamber.set_power(True)


def test_an_rs485_address_prefixes_every_request() -> None:
    context, protocol = talk(line_protocol("espec-p300", {"request_prefix": "3,"}),
                             [(b"3,TEMP?\r\n", b"20.0,20.0,180.0,-70.0\r\n")])
    with context as line:
        assert LineChamber(line, "memory", protocol).read_temperature_c() == 20.0


@pytest.mark.parametrize(("profile", "sent", "reply", "message"), [
    ("espec-p300", b"TEMP, S25.0\r\n", b"NA:PROTECT ON\r\n",
     r"chamber \(memory\): 'TEMP, S25.0' refused: 'NA:PROTECT ON' \(the controller's data protection is on"),
    ("espec-p300", b"TEMP, S25.0\r\n", b"NA:CONT NOT READY-1\r\n",
     r"refused: 'NA:CONT NOT READY-1' \(the chamber does not support PTCON or humidity\)"),
    ("espec-p300", b"TEMP, S25.0\r\n", b"NA:DATA OUT OF RANGE\r\n", r"refused: 'NA:DATA OUT OF RANGE' \(value beyond"),
    ("simserv", b"11001\xb61\xb61\xb625.0\r", b"-6\r\n",
     r"chamber \(memory\): '11001¶1¶1¶25.0' refused: '-6' \(too few or incorrect parameters\)"),
])
def test_a_refusal_is_one_line_with_what_the_code_means(profile: str, sent: bytes, reply: bytes,
                                                         message: str) -> None:
    context, protocol = talk(profile, [(sent, reply)])
    with context as line:
        with pytest.raises(InstrumentError, match=message):
            LineChamber(line, "memory", protocol).write_setpoint_c(25.0)


def test_a_garbled_reply_is_transient_and_silence_a_timeout() -> None:
    context, protocol = talk("thermotron-8800", [(b"PVAR1?\r", b"2\x003.5\r\n"), (b"PVAR1?\r", None)])
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        with pytest.raises(TransientInstrumentError, match=r"chamber \(memory\): 'PVAR1\?': unexpected reply"):
            chamber.read_temperature_c()
        with pytest.raises(TransientInstrumentError, match=r"'PVAR1\?': no reply within the timeout"):
            chamber.read_temperature_c()


def test_a_controller_in_fahrenheit_is_refused_at_identify() -> None:
    context, protocol = talk("watlow-f4t-scpi", [(b"*IDN?\n", b"Watlow F4T\n"), (b":UNIT:TEMPERATURE?\n", b"F\n")])
    with context as line:
        with pytest.raises(InstrumentError, match=r"chamber \(memory\): controller is not in °C \(units read 'F'"):
            LineChamber(line, "memory", protocol).identify()


def test_a_value_no_chamber_reads_is_refused() -> None:
    context, protocol = talk("thermotron-8800", [(b"PVAR1?\r", b"1832.0\r\n")])
    with context as line:
        with pytest.raises(InstrumentError, match=r"process value reads 1832 °C: not a chamber's air"):
            LineChamber(line, "memory", protocol).read_temperature_c()


def test_limits_that_are_not_a_range_are_refused() -> None:
    context, protocol = talk("espec-p300", [(b"TEMP?\r\n", b"20.0,20.0,-70.0,180.0\r\n")] * 2)
    with context as line:
        with pytest.raises(InstrumentError, match=r"set point limits read 180…-70 °C: not a range"):
            LineChamber(line, "memory", protocol).controller_limits_c()


@pytest.mark.parametrize("profile", sorted(LINE_PROFILES))
@pytest.mark.parametrize("setpoint_c", [float("nan"), float("inf"), float("-inf")])
def test_a_set_point_that_is_no_number_is_refused_before_the_wire(profile: str, setpoint_c: float) -> None:
    context, protocol = talk(profile, [])  # nothing may be written
    with context as line:
        chamber = LineChamber(line, "memory", protocol)
        with pytest.raises(InstrumentError, match=rf"^chamber \(memory\): setpoint {setpoint_c:g} °C refused: not a "
                                                  r"finite number \(nothing was sent\)$"):
            chamber.write_setpoint_c(setpoint_c)
