"""The Modbus chamber driver against exact RTU frames, in memory (no serial port, no socket): what a Watlow
F4 or F4T on an RS-485 line receives and answers, CRC included."""

from __future__ import annotations

import struct

import pytest
from pymodbus.client import ModbusSerialClient

from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import ControllerLimits, controller_limits
from accelcal_rig.instruments.chamber_modbus import ModbusChamber
from accelcal_rig.protocols.chamber_registers import register_map
from tests.instruments.expected_protocol import ExpectedPort


def crc16(frame: bytes) -> bytes:
    """Modbus RTU CRC (polynomial 0xA001 reflected, initial 0xFFFF), low byte first — written from the spec."""
    crc = 0xFFFF
    for byte in frame:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return struct.pack("<H", crc)


def read_request(device: int, address: int, count: int) -> bytes:
    body = bytes([device, 0x03]) + struct.pack(">HH", address, count)
    return body + crc16(body)


def read_reply(device: int, *words: int) -> bytes:
    body = bytes([device, 0x03, 2 * len(words)]) + b"".join(struct.pack(">H", w) for w in words)
    return body + crc16(body)


def float_words_low_first(value: float) -> tuple[int, int]:
    high, low = struct.unpack(">HH", struct.pack(">f", value))
    return low, high


def chamber(conversation, profile: str = "watlow-f4t", device_id: int = 1) -> tuple[ModbusChamber, ExpectedPort]:
    client = ModbusSerialClient("memory", baudrate=9600, timeout=0.05, retries=0)
    port = ExpectedPort(conversation)
    client.socket = port  # type: ignore[assignment]
    return ModbusChamber(client, "modbus-rtu memory", register_map(profile), device_id), port


def test_the_crc_of_a_known_frame() -> None:
    assert crc16(bytes.fromhex("010300000001")) == bytes.fromhex("840A")  # a textbook frame


def test_f4t_float_words_low_first_byte_for_byte() -> None:
    pv, sp = float_words_low_first(24.5), float_words_low_first(-40.0)
    driver, port = chamber([(read_request(1, 2820, 2), read_reply(1, *pv)),
                            (read_request(1, 2782, 2), read_reply(1, *sp))])
    assert driver.read_temperature_c() == 24.5
    assert driver.read_setpoint_c() == -40.0
    port.assert_finished()


def write_multiple_request(device: int, address: int, words: tuple[int, ...]) -> bytes:
    body = bytes([device, 0x10]) + struct.pack(">HHB", address, len(words), 2 * len(words)) + b"".join(
        struct.pack(">H", w) for w in words)
    return body + crc16(body)


def write_multiple_reply(device: int, address: int, count: int) -> bytes:
    body = bytes([device, 0x10]) + struct.pack(">HH", address, count)
    return body + crc16(body)


def test_a_setpoint_is_written_as_both_float_words_in_one_request() -> None:
    words = float_words_low_first(60.0)
    driver, port = chamber([(write_multiple_request(1, 2782, words), write_multiple_reply(1, 2782, 2))])
    driver.write_setpoint_c(60.0)
    port.assert_finished()


def test_f4_identity_decimals_units_then_values_as_scaled_integers() -> None:
    conversation = [(read_request(5, 0, 1), read_reply(5, 5270)), (read_request(5, 606, 1), read_reply(5, 1)),
                    (read_request(5, 901, 1), read_reply(5, 1)), (read_request(5, 100, 1), read_reply(5, 235)),
                    (read_request(5, 300, 1), read_reply(5, 0xFE70)),                      # −40.0 °C
                    (write_multiple_request(5, 300, (600,)), write_multiple_reply(5, 300, 1))]
    driver, port = chamber(conversation, profile="watlow-f4", device_id=5)
    assert driver.identify() == "scaled-int16 controller (model 5270, PV 23.5 °C, SP -40.0 °C)"
    driver.write_setpoint_c(60.0)
    port.assert_finished()


def test_a_wrong_model_is_named() -> None:
    driver, _ = chamber([(read_request(1, 0, 1), read_reply(1, 5271))], profile="watlow-f4")
    with pytest.raises(InstrumentError, match="register 0 reads 5271, the map expects model 5270"):
        driver.identify()


def test_an_exception_reply_is_a_refusal_and_busy_is_transient() -> None:
    def exception(device: int, function: int, code: int) -> bytes:
        body = bytes([device, function | 0x80, code])
        return body + crc16(body)

    driver, _ = chamber([(read_request(1, 2820, 2), exception(1, 0x03, 0x02)),
                         (read_request(1, 2820, 2), exception(1, 0x03, 0x06))])
    with pytest.raises(InstrumentError, match="register 2820 refused"):
        driver.read_temperature_c()
    with pytest.raises(TransientInstrumentError, match="busy reading register 2820"):
        driver.read_temperature_c()


def test_silence_is_a_lost_reply_to_reconnect_after() -> None:
    driver, _ = chamber([(read_request(1, 2820, 2), None)])
    with pytest.raises(TransientInstrumentError, match="no reply reading register 2820") as error:
        driver.read_temperature_c()
    assert error.value.reconnect


def test_f4_reads_its_own_setpoint_limits_from_602_and_603() -> None:
    driver, port = chamber([(read_request(1, 602, 1), read_reply(1, 0xFD44)),   # −70.0 °C
                            (read_request(1, 603, 1), read_reply(1, 1800))],    # 180.0 °C
                           profile="watlow-f4")
    assert driver.controller_limits_c() == (-70.0, 180.0)
    port.assert_finished()


def test_limits_that_are_no_range_are_refused_and_a_map_without_them_says_none() -> None:
    driver, _ = chamber([(read_request(1, 602, 1), read_reply(1, 500)), (read_request(1, 603, 1), read_reply(1, 400))],
                        profile="watlow-f4")
    with pytest.raises(InstrumentError, match=r"set point limits read 50…40 °C \(registers 602/603\): not a range"):
        driver.controller_limits_c()
    client = ModbusSerialClient("memory", baudrate=9600, timeout=0.05, retries=0)
    without = ModbusChamber(client, "modbus-rtu memory",
                            register_map("watlow-f4t", {"setpoint_low_register": None, "setpoint_high_register": None}))
    assert not isinstance(without, ControllerLimits) and controller_limits(without) is None


def test_f4t_reads_its_own_setpoint_limits_from_2774_and_2776_as_floats() -> None:
    """ESPEC's ChamberConnectLibrary (watlowf4t.py get_loop_range): loop 1's low limit at 2774, high at 2776."""
    driver, port = chamber([(read_request(1, 2774, 2), read_reply(1, *float_words_low_first(-70.0))),
                            (read_request(1, 2776, 2), read_reply(1, *float_words_low_first(180.0)))])
    assert driver.controller_limits_c() == (-70.0, 180.0)
    port.assert_finished()


@pytest.mark.parametrize("profile", ["watlow-f4", "watlow-f4t"])
def test_a_set_point_that_is_no_number_is_refused_before_the_wire(profile: str) -> None:
    driver, port = chamber([], profile=profile)  # nothing may be written
    with pytest.raises(InstrumentError, match=r"^chamber \(modbus-rtu memory\): setpoint nan °C refused: not a finite "
                                              r"number \(nothing was sent\)$"):
        driver.write_setpoint_c(float("nan"))
    port.assert_finished()
