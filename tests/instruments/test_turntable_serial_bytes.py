"""The serial turntable driver against exact request/reply bytes, in memory (no pty): the line protocol
as the controller sees it."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.turntable_line import ACCELCAL_LINE, turntable_protocol
from tests.instruments.expected_protocol import expected_protocol


def table(line, n_axes: int = 3, protocol=ACCELCAL_LINE) -> SerialTurntable:
    return SerialTurntable(line, "memory", protocol, n_axes)


def test_identify_move_and_read_angles_byte_for_byte() -> None:
    with expected_protocol([(b"*IDN?\n", b"ACME TT-3 v1.2\n"),
                            (b"MOV 1 0.00000\n", b"OK\n"), (b"MOV 2 90.00000\n", b"OK\n"),
                            (b"MOV 3 -45.12346\n", b"OK\n"),
                            (b"POS? 1\n", b"0.000000\n"), (b"POS? 2\n", b"89.999990\n"), (b"POS? 3\n", b"-4.5e1\n")]) as line:
        driver = table(line)
        assert driver.identify() == "ACME TT-3 v1.2"
        driver.move_to(np.array([0.0, 90.0, -45.123456]))
        np.testing.assert_array_equal(driver.read_angles_deg(), [0.0, 89.99999, -45.0])


def test_in_position_asks_for_faults_first_then_busy() -> None:
    with expected_protocol([(b"FAULT?\n", b"0\n"), (b"BUSY?\n", b"1\n"),
                            (b"FAULT?\n", b"0\n"), (b"BUSY?\n", b"0\n")]) as line:
        driver = table(line)
        assert not driver.in_position()
        assert driver.in_position()


def test_a_controller_fault_is_raised_not_waited_out() -> None:
    with expected_protocol([(b"FAULT?\n", b"7\n")]) as line:
        with pytest.raises(InstrumentError, match=r"turntable \(memory\): controller fault 7"):
            table(line).in_position()


def test_an_error_reply_is_a_refusal_and_a_garbled_one_is_transient() -> None:
    with expected_protocol([(b"MOV 1 400.00000\n", b"ERR 3 limit\n"), (b"STOP\n", b"OK?\n")]) as line:
        driver = table(line, n_axes=1)
        with pytest.raises(InstrumentError, match=r"'MOV 1 400.00000' refused: 'ERR 3 limit'"):
            driver.move_to(np.array([400.0]))
        with pytest.raises(TransientInstrumentError, match=r"'STOP': unexpected reply 'OK\?'"):
            driver.stop()


def test_silence_is_a_timeout() -> None:
    with expected_protocol([(b"*IDN?\n", None)]) as line:
        with pytest.raises(TransientInstrumentError, match=r"'\*IDN\?': no reply within the timeout"):
            table(line).identify()


def test_of_several_lines_only_the_last_answers() -> None:
    with expected_protocol([(b"BUSY?\n", None), (b"FAULT?\n", b"1\n0\n"), (b"BUSY?\n", b"0\n")]) as line:
        driver = table(line)
        with pytest.raises(TransientInstrumentError):
            driver._ask(ACCELCAL_LINE.busy)  # its reply comes late, with the next one
        assert driver.in_position()


def test_a_profile_with_other_templates_and_terminators() -> None:
    crlf = turntable_protocol("accelcal-line", {"write_terminator": "\r\n", "read_terminator": "\r\n",
                                                "move": {"send": "AX{axis}:POS {angle:.3f}", "reply": "ACK",
                                                         "answer": "ACK"}})
    with expected_protocol([(b"AX1:POS 12.500\r\n", b"ACK\r\n")], write_terminator="\r\n",
                            read_terminator="\r\n") as line:
        table(line, n_axes=1, protocol=crlf).move_to(np.array([12.5]))


@pytest.mark.parametrize("protocol", ["accelcal-line", "acutrol3000"])
def test_a_move_or_rate_that_is_no_number_is_refused_before_anything_is_sent(protocol: str) -> None:
    with expected_protocol([]) as line:  # nothing may be written, not even the profile's setup
        driver = table(line, protocol=turntable_protocol(protocol))
        with pytest.raises(InstrumentError, match=r"^turntable \(memory\): axis 2 to nan° refused: not a finite "
                                                  r"number \(nothing was sent\)$"):
            driver.move_to(np.array([0.0, np.nan, 0.0]))
        with pytest.raises(InstrumentError, match=r"^turntable \(memory\): axis 1 at inf °/s refused"):
            driver.rotate_at(0, float("inf"), 10.0)  # type: ignore[attr-defined]
        with pytest.raises(InstrumentError, match=r"^turntable \(memory\): axis 1 acceleration nan °/s² refused"):
            driver.rotate_at(0, 10.0, float("nan"))  # type: ignore[attr-defined]
