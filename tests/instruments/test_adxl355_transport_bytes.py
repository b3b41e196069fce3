"""The ADXL355 bridge protocol against exact request/reply bytes, in memory (no pty), and the driver's
register traffic on top of it."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import CaptureOverflow, SerialBridge, SpidevBus
from accelcal_rig.parts.adxl35x import ADXL355, ADXL357
from tests.instruments.expected_protocol import expected_protocol


def bridge(line) -> SerialBridge:
    return SerialBridge(line, "memory")


def test_register_reads_and_writes_byte_for_byte() -> None:
    with expected_protocol([(b"R 00 4\n", b"=AD1DED01\n"), (b"W 2C 01\n", b"=\n")]) as line:
        transport = bridge(line)
        assert transport.read(0x00, 4) == bytes([0xAD, 0x1D, 0xED, 0x01])
        transport.write(0x2C, 0x01)


@pytest.mark.parametrize(("reply", "message"), [
    (b"=AD1D\n", r"read of 4 bytes at 0x00 answered '=AD1D'"),   # short
    (b"=AD1DEZ01\n", r"garbled reply '=AD1DEZ01'"),              # not hex
    (b"AD1DED01\n", r"garbled reply 'AD1DED01'"),                 # no "="
])
def test_a_spoilt_read_is_transient(reply: bytes, message: str) -> None:
    with expected_protocol([(b"R 00 4\n", reply)]) as line:
        with pytest.raises(TransientInstrumentError, match=message):
            bridge(line).read(0x00, 4)


def test_a_refusal_names_the_request() -> None:
    with expected_protocol([(b"W 2D 00\n", b"!not in standby\n")]) as line:
        with pytest.raises(InstrumentError, match=r"'W 2D 00' refused: not in standby"):
            bridge(line).write(0x2D, 0x00)


def test_capture_start_and_fetch_carry_the_temperatures() -> None:
    first, second = adxl355.encode_fifo(np.array([[1, 2, 3]])), adxl355.encode_fifo(np.array([[4, 5, 6]]))
    with expected_protocol([(b"C 2\n", b"=075D\n"), (b"G 0\n", b"=" + first.hex().upper().encode() + b"\n"),
                            (b"G 1\n", b"=" + second.hex().upper().encode() + b"T075C\n")]) as line:
        transport = bridge(line)
        assert transport.start_capture(2) == 0x75D
        assert transport.fetch_capture(0) == (first, None)
        assert transport.fetch_capture(1) == (second, 0x75C)


def test_a_capture_that_lost_samples_is_an_overflow() -> None:
    with expected_protocol([(b"G 0\n", b"!overflow at sample 40\n")]) as line:
        with pytest.raises(CaptureOverflow, match="overflow at sample 40"):
            bridge(line).fetch_capture(0)


def test_the_driver_configures_the_part_its_table_describes() -> None:
    """An ADXL357 at ±20 g and 125 Hz: RANGE code 0b10, FILTER code 5, both read back, in standby only."""
    with expected_protocol([(b"R 2D 1\n", b"=01\n"), (b"W 2C 02\n", b"=\n"), (b"W 28 05\n", b"=\n"),
                            (b"R 28 1\n", b"=05\n"), (b"R 2C 1\n", b"=82\n")]) as line:
        Adxl355(bridge(line), "X-1", VirtualClock(), ADXL357).configure({"accel": 20}, 125.0)


def test_the_driver_reads_temperature_with_its_part_s_format_twice_in_agreement() -> None:
    with expected_protocol([(b"R 06 2\n", b"=075D\n"), (b"R 06 2\n", b"=075C\n")]) as line:
        assert Adxl355(bridge(line), "X-1", VirtualClock(), ADXL355).read_temperature_c() == pytest.approx(
            25.0 + 1 / 9.05)  # the later of two reads a bit apart


def test_a_torn_temperature_read_is_outvoted() -> None:
    # TEMP2/TEMP1 are not double-buffered: 0x085D is 0x075D with the high nibble one step ahead (~28 °C off).
    with expected_protocol([(b"R 06 2\n", b"=085D\n"), (b"R 06 2\n", b"=075D\n"), (b"R 06 2\n", b"=075D\n")]) as line:
        assert Adxl355(bridge(line), "X-1", VirtualClock(), ADXL355).read_temperature_c() == pytest.approx(25.0)


def test_temperature_reads_that_never_agree_are_a_transient_fault() -> None:
    replies = [(b"R 06 2\n", b"=085D\n" if k % 2 else b"=075D\n") for k in range(10)]
    with expected_protocol(replies) as line, pytest.raises(InstrumentError, match="no two consecutive ones"):
        Adxl355(bridge(line), "X-1", VirtualClock(), ADXL355).read_temperature_c()


class ExpectedSpi:
    """Stands in for a spidev.SpiDev: each xfer2 must send the next expected bytes; it answers in kind."""

    def __init__(self, conversation: list[tuple[list[int], list[int]]]) -> None:
        self._left = conversation

    def xfer2(self, sent: list[int]) -> list[int]:
        expected, answer = self._left.pop(0)
        assert sent == expected, f"sent {sent}, expected {expected}"
        return answer

    def close(self) -> None:
        pass


def test_spidev_command_bytes_read_and_write() -> None:
    """Mode 0 SPI: (address << 1) | 1 reads a burst, address << 1 writes one register."""
    spi = ExpectedSpi([([0x01, 0, 0, 0, 0], [0x00, 0xAD, 0x1D, 0xED, 0x01]), ([0x2C << 1, 0x01], [0, 0])])
    bus = SpidevBus(spi, "spidev 0.1")
    assert bus.read(0x00, 4) == bytes([0xAD, 0x1D, 0xED, 0x01])
    bus.write(0x2C, 0x01)
    assert not spi._left
