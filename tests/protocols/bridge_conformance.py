"""The serial bridge protocol's conformance table: requests and the replies docs/instruments.md promises for them
("The serial bridge protocol", its table of refusals), in order, from a bridge just started (the part at its
reset values, in standby). tests/firmware/test_bridge_conformance.py sends it to the reference firmware's host
build and to the Python simulator, for each part, and asserts they answer alike.

A row's reply is the exact line, a pattern the whole line must match (where the part's data decide it: a
temperature, samples, a count of samples captured so far), or NO_REPLY (a line that is no request)."""

from __future__ import annotations

import re
from dataclasses import dataclass

#: The row's request gets no reply at all.
NO_REPLY = None
#: Stands for the part's greeting in the rows below (`exchanges` puts the part's pattern in its place).
GREETING_PLACEHOLDER = re.compile("<greeting>")

GREETING = {
    "adxl355": re.compile(r"ADXL355-BRIDGE 3 part=adxl355 capture=4096 accelcal-rig .+"),
    "icm42688p": re.compile(r"ADXL355-BRIDGE 3 part=icm42688p capture=2304 accelcal-rig .+"),
}


@dataclass(frozen=True)
class Exchange:
    """One request line (sent as is, then its LF) and what the bridge answers."""

    send: bytes
    reply: str | re.Pattern[str] | None
    why: str


def _row(send: str | bytes, reply: str | re.Pattern[str] | None, why: str) -> Exchange:
    return Exchange(send.encode("ascii") if isinstance(send, str) else send, reply, why)


def _hex(digits: int) -> re.Pattern[str]:
    return re.compile(f"=[0-9A-F]{{{digits}}}")


def line_rows(identity: str, identity_reply: str) -> list[Exchange]:
    """How a line becomes a request: its bytes, its length, its words (`identity`: a one-register read whose reply,
    `identity_reply`, the part fixes)."""
    exactly_64 = identity.replace(" 1", " " + "0" * (64 - len(identity)) + "1")
    assert len(exactly_64) == 64
    return [
        _row("", NO_REPLY, "an empty line is no request"),
        _row("   ", NO_REPLY, "nor is a line of spaces"),
        _row("\r", NO_REPLY, "nor a terminal's CR LF alone"),
        _row(identity + "\r", identity_reply, "CR LF ends a line as LF does"),
        _row(identity.replace(" ", " \r", 1), identity_reply, "a CR is dropped wherever it is"),
        _row("  " + identity.replace(" ", "   ") + "  ", identity_reply, "words are split at runs of spaces"),
        _row(identity.replace("\x20", "\t", 1), "!not printable ASCII", "a tab is no separator: not printable"),
        _row(identity.encode("ascii") + b"\x00", "!not printable ASCII", "a NUL would cut the line short unseen"),
        _row(b"\xff\xfe?", "!not printable ASCII", "bytes above 0x7E"),
        _row(b"\x1b[A", "!not printable ASCII", "a terminal's arrow key"),
        _row(exactly_64, identity_reply, "64 bytes is the longest line (leading zeros in a count are fine)"),
        _row(exactly_64 + "1", "!line too long", "65 bytes are refused"),
        _row("R 00 1 " * 700, "!line too long", "a 4900-byte line is refused once, never echoed"),
        _row(bytes(b for b in range(256) if b != 0x0A) * 20, "!line too long",
             "5100 binary bytes (every byte but LF): the length is checked first"),
        _row("?", GREETING_PLACEHOLDER, "the line after a refused one is read afresh"),
    ]



def request_rows() -> list[Exchange]:
    """Verbs, word counts and argument syntax: the same for every part."""
    return [
        _row("HELLO", "!unknown request (? R W C G)", "unknown verb"),
        _row("r 00 1", "!unknown request (? R W C G)", "verbs are upper case"),
        _row("RR 00 1", "!unknown request (? R W C G)", "a verb is one character"),
        _row("? x", "!usage: ?", "the greeting takes no argument"),
        _row("R", "!usage: R <addr> <count>", "R without arguments"),
        _row("R 00", "!usage: R <addr> <count>", "R without a count"),
        _row("R 00 1 2", "!usage: R <addr> <count>", "R with an extra argument"),
        _row("W 1E", "!usage: W <addr> <value>", "W without a value"),
        _row("W 1E 00 00", "!usage: W <addr> <value>", "W with an extra argument"),
        _row("C", "!usage: C <count>", "C without a count"),
        _row("C 1 2", "!usage: C <count>", "C with an extra argument"),
        _row("G", "!usage: G <first>", "G without an index"),
        _row("G 0 0", "!usage: G <first>", "G with an extra argument"),
        _row("R 80 1", "!bad address (hex 00..7F)", "addresses are 7 bits"),
        _row("R 000 1", "!bad address (hex 00..7F)", "at most two hex digits"),
        _row("R 0x00 1", "!bad address (hex 00..7F)", "no 0x prefix"),
        _row("R -1 1", "!bad address (hex 00..7F)", "no sign"),
        _row("R G0 1", "!bad address (hex 00..7F)", "not hex"),
        _row("R 00 0", "!bad count (decimal 1..288)", "a count of 0"),
        _row("R 00 -1", "!bad count (decimal 1..288)", "a negative count"),
        _row("R 00 +1", "!bad count (decimal 1..288)", "a signed count"),
        _row("R 00 289", "!bad count (decimal 1..288)", "more than the whole FIFO (288 bytes)"),
        _row("R 00 99999999999999999999", "!bad count (decimal 1..288)", "a huge count"),
        _row("R 00 1F", "!bad count (decimal 1..288)", "counts are decimal"),
        _row("R 00 1.5", "!bad count (decimal 1..288)", "not a whole number"),
        _row("W 80 00", "!bad address (hex 00..7F)", "W's address is checked as R's"),
        _row("W 1E 100", "!bad value (hex 00..FF)", "a value is one byte"),
        _row("W 1E -1", "!bad value (hex 00..FF)", "no sign"),
        _row("W 1E zz", "!bad value (hex 00..FF)", "not hex"),
    ]


def adxl355_rows() -> list[Exchange]:
    """The ADXL355's register map (0x00…0x2F; 0x00…0x1D read-only), its standby rule and the bridge's capture."""
    def stopped(register: int) -> re.Pattern[str]:
        return re.compile(rf"!capture stopped: register 0x{register:02X} written after \d+ of 100 samples")

    return [
        _row("R 00 4", "=AD1DED01", "identity: DEVID_AD, DEVID_MST, PARTID, REVID"),
        _row("R 0 1", "=AD", "one hex digit is an address"),
        _row("R 2c 1", "=81", "lower-case hex: RANGE at its reset value"),
        _row("R 2E 2", "=0000", "SELF_TEST and RESET, the last registers"),
        _row("R 2E 4", "!no register 0x30", "a burst past the map's end is refused, not padded"),
        _row("R 30 1", "!no register 0x30", "a register past the map"),
        _row("R 7F 1", "!no register 0x7F", "the last address is no ADXL355 register"),
        _row("R 00 288", "!no register 0x30", "a long burst from 0x00 runs past the map"),
        _row("R 11 288", "=" + "000002" * 96, "a burst from FIFO_DATA stays there: an empty FIFO, 96 empty entries"),
        _row("R 10 288", "!no register 0x30", "a burst into FIFO_DATA from below auto-increments past it"),
        _row("R 10 2", "=0000", "ZDATA1 and FIFO_DATA inside a burst (which reads 0)"),
        _row("W 00 00", "!read-only register 0x00", "DEVID_AD is read-only"),
        _row("W 11 00", "!read-only register 0x11", "FIFO_DATA is read-only"),
        _row("W 1D 00", "!read-only register 0x1D", "0x12…0x1D (reserved) are read-only"),
        _row("W 30 00", "!no register 0x30", "a write past the map"),
        _row("W 7F 00", "!no register 0x7F", "the last address"),
        _row("W 1E 5A", "=", "OFFSET_X_H is writable"),
        _row("R 1E 1", "=5A", "and reads back"),
        _row("W 1e a5", "=", "lower-case hex"),
        _row("R 1E 1", "=A5", "reads back in upper case"),
        _row("G 0", "!no capture (start one with C)", "G before any C"),
        _row("C 10", "!capture needs the part measuring", "C in standby"),
        _row("C 0", "!bad count (decimal 1..4096)", "a capture of nothing"),
        _row("C 4097", "!bad count (decimal 1..4096)", "more than the buffer (capture=4096)"),
        _row("C -5", "!bad count (decimal 1..4096)", "a negative count"),
        _row("C 99999999999999999999", "!bad count (decimal 1..4096)", "a huge count"),
        _row("G -1", "!bad first (decimal 0..4096)", "a negative index"),
        _row("G 4097", "!bad first (decimal 0..4096)", "past the buffer"),
        _row("W 2C 82", "=", "RANGE ±4 g, in standby"),
        _row("W 28 0A", "=", "FILTER 3.906 Hz (slow: a capture stays running through the table)"),
        _row("W 2D 00", "=", "measure"),
        _row("W 2C 81", "!register 0x2C changes only in standby", "RANGE while measuring"),
        _row("W 28 00", "!register 0x28 changes only in standby", "FILTER while measuring"),
        _row("R 28 5", "=0A60000082", "the refused writes changed nothing (FILTER, FIFO_SAMPLES, …, RANGE)"),
        _row("C 100", _hex(4), "C answers TEMP2, TEMP1 as it starts"),
        _row("G 0", re.compile(r"=([0-9A-F]{18})*"), "G while capturing: the samples so far, no T yet"),
        _row("G 4096", "=", "from past the samples so far: none"),
        _row("R 11 9", "!FIFO_DATA is being captured (fetch with G)", "the FIFO is the capture's"),
        _row("R 00 18", "!FIFO_DATA is being captured (fetch with G)", "so is a burst that covers it"),
        _row("R 00 4", "=AD1DED01", "other registers are not"),
        _row("W 29 60", "=", "FIFO_SAMPLES written during a capture"),
        _row("G 0", stopped(0x29), "ends it, and G says so"),
        _row("R 11 9", _hex(18), "the FIFO is free again"),
        _row("C 0", "!bad count (decimal 1..4096)", "a refused C…"),
        _row("G 0", "!no capture (start one with C)", "…forgets the capture before it"),
        _row("C 100", _hex(4), "a new capture"),
        _row("W 2D 01", "=", "standby during it"),
        _row("G 0", stopped(0x2D), "ends it"),
        _row("W 2F 00", "=", "RESET with any code but 0x52 is passed on (the part ignores it)"),
        _row("R 2C 2", "=8201", "nothing was reset"),
        _row("W 2F 52", "=", "RESET"),
        _row("R 2C 2", "=8101", "RANGE and POWER_CTL at their reset values"),
        _row("G 0", stopped(0x2D), "a reset forgets no capture's end"),
        _row("C 10", "!capture needs the part measuring", "standby after the reset"),
        _row("G 0", "!no capture (start one with C)", "the refused C forgot it"),
    ]


def icm42688p_rows() -> list[Exchange]:
    """The ICM-42688-P's bank 0 (0x00…0x7F as modelled; read-only TEMP_DATA1…FIFO_DATA and WHO_AM_I), bank
    selection, and the bridge's capture of its FIFO packets."""
    return [
        _row("R 75 1", "=47", "WHO_AM_I"),
        _row("R 4f 2", "=0606", "lower-case hex: both CONFIG0 at their reset values"),
        _row("R 7F 1", "=00", "the last address"),
        _row("R 7F 2", "!no register 0x80", "a burst past the address space"),
        _row("R 00 128", _hex(256), "the whole map"),
        _row("R 00 129", "!no register 0x80", "one more"),
        _row("R 00 288", "!no register 0x80", "the longest count"),
        _row("W 75 00", "!read-only register 0x75", "WHO_AM_I is read-only"),
        _row("W 1D 00", "!read-only register 0x1D", "TEMP_DATA1 is read-only"),
        _row("W 2D 00", "!read-only register 0x2D", "INT_STATUS is read-only"),
        _row("W 2E 00", "!read-only register 0x2E", "FIFO_COUNTH is read-only"),
        _row("W 30 00", "!read-only register 0x30", "FIFO_DATA is read-only"),
        _row("R 4C 1", "=30", "INTF_CONFIG0 at reset: the FIFO count in bytes, big-endian"),
        _row("R 30 288", "=" + "FF" * 288, "a burst from FIFO_DATA stays there: an empty FIFO reads 0xFF"),
        _row("W 50 6C", "=", "ACCEL_CONFIG0 with a low-power ODR code is passed on"),
        _row("W 50 E0", "=", "and a reserved FS_SEL and ODR code"),
        _row("R 50 1", "=E0", "the part holds what was written"),
        _row("W 4E 0F", "=", "both sensors on, low noise"),
        _row("R 1D 17", _hex(34), "a sample and INT_STATUS in one burst"),
        _row("W 76 01", "=", "bank 1"),
        _row("R 75 1", "=00", "banks 1…4 are not modelled: they read 0"),
        _row("W 75 00", "=", "read-only is bank 0's fact: in bank 1 the write is passed on"),
        _row("R 76 1", "=01", "REG_BANK_SEL is in every bank"),
        _row("?", GREETING_PLACEHOLDER, "a greeting selects bank 0 before it looks for the part again"),
        _row("R 76 1", "=00", "so bank 0 it is"),
        _row("W 75 00", "!read-only register 0x75", "and WHO_AM_I is read-only again"),
        _row("W 76 01", "=", "bank 1 again"),
        _row("W 76 00", "=", "bank 0 by hand"),
        _row("R 75 1", "=47", "WHO_AM_I"),
        _row("G 0", "!no capture (start one with C)", "G before any C"),
        _row("C 10", "!capture needs the FIFO on with both sensors (FIFO_CONFIG 00, FIFO_CONFIG1 00)",
             "measuring, but the FIFO is off"),
        _row("C 0", "!bad count (decimal 1..2304)", "a capture of nothing"),
        _row("C 2305", "!bad count (decimal 1..2304)", "more than the buffer (capture=2304: 36 kB of 16-byte packets)"),
        _row("G 2305", "!bad first (decimal 0..2304)", "past the buffer"),
        _row("W 50 6B", "=", "ACCEL_CONFIG0 12.5 Hz (slow: a capture stays running through the table)"),
        _row("W 4F 0B", "=", "GYRO_CONFIG0 the same rate"),
        _row("W 5F 08", "=", "FIFO_CONFIG1 with a timestamp/FSYNC bit but neither sensor"),
        _row("W 16 80", "=", "FIFO_CONFIG stop-on-full"),
        _row("C 10", "!capture needs the FIFO on with both sensors (FIFO_CONFIG 80, FIFO_CONFIG1 08)",
             "the FIFO on, but not in packets of both sensors"),
        _row("W 5F 07", "=", "FIFO_CONFIG1: accelerometer, gyroscope, temperature (packet 3)"),
        _row("R 16 1", "=80", "FIFO_CONFIG holds what was written"),
        _row("C 100", _hex(4), "C answers TEMP_DATA1, TEMP_DATA0 as it starts"),
        _row("G 0", re.compile(r"=([0-9A-F]{32})*"), "G while capturing: the packets so far, no T yet"),
        _row("G 2304", "=", "from past the packets so far: none"),
        _row("R 30 16", "!FIFO_DATA is being captured (fetch with G)", "the FIFO is the capture's"),
        _row("R 2D 4", "!FIFO_DATA is being captured (fetch with G)", "so is a burst that covers it"),
        _row("R 1D 16", _hex(32), "the data registers are not"),
        _row("W 4E 00", "=", "both sensors off during it"),
        _row("G 0", re.compile(r"!capture stopped: register 0x4E written after \d+ of 100 samples"), "ends it"),
        _row("C 10", "!capture needs the part measuring", "the sensors are off"),
        _row("G 0", "!no capture (start one with C)", "the refused C forgot it"),
        _row("C", "!usage: C <count>", "the words before anything else"),
        _row("W 11 01", "=", "soft reset"),
        _row("R 4F 2", "=0606", "CONFIG0 at their reset values"),
    ]


def exchanges(part: str) -> list[Exchange]:
    """The whole table for `part`, in the order it is sent."""
    identity, identity_reply = {"adxl355": ("R 00 1", "=AD"), "icm42688p": ("R 75 1", "=47")}[part]
    rows = [_row("?", GREETING[part], "the greeting names protocol 3 and the part"),
            *line_rows(identity, identity_reply), *request_rows(),
            *(adxl355_rows() if part == "adxl355" else icm42688p_rows())]
    return [Exchange(row.send, GREETING[part], row.why) if row.reply is GREETING_PLACEHOLDER else row for row in rows]
