"""Request/reply over a serial line (a device path or any pyserial URL), one line each way.

pyserial's read_until reads a byte per system call; replies here can be hundreds of characters (a FIFO
burst in hex), so lines are read in whatever chunks have arrived. The wall clock bounds a reply: it is
the wire's timeout, not campaign time (which is virtual in a dry run).
"""

from __future__ import annotations

import time

import serial

from accelcal_rig.core.descriptors import read_within, write_within
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.protocols.acl_blocks import PREFIX_BYTES, is_block, looks_like_prefix, prefix


class LinePort:
    def __init__(self, port: serial.SerialBase, name: str, write_terminator: str = "\n",
                 read_terminator: str = "\n", endpoint: str = "", baudrate: int = 9600,
                 encoding: str = "ascii") -> None:
        self._port = port
        self._endpoint, self._baudrate = endpoint, baudrate
        self.name = name  # "turntable (serial /dev/ttyUSB0)": how errors name the instrument
        self._encoding = encoding  # latin-1 where a protocol separates fields with a byte above 0x7F
        self._write_terminator = write_terminator.encode(encoding)
        self._read_terminator = read_terminator.encode(encoding)

    @classmethod
    def open(cls, endpoint: str, instrument: str, baudrate: int, timeout_s: float, write_terminator: str = "\n",
             read_terminator: str = "\n", encoding: str = "ascii") -> LinePort:
        """A device path or pyserial URL; `socket://host:port` is a TCP connection, named as one."""
        name = f"{instrument} ({describe_endpoint(endpoint)})"
        return cls(_open_port(name, endpoint, baudrate, timeout_s), name, write_terminator, read_terminator,
                   endpoint, baudrate, encoding)

    def ask(self, request: str) -> str:
        """Send one request, return its reply line without the terminator (stripped)."""
        self.send(request)
        return self.receive(request)

    def receive(self, request: str) -> str:
        """The reply line to `request`, sent before (by `send`): requests to several ports can be sent
        first and their replies collected after, so the devices answer at the same time."""
        try:
            raw = self._read_line()
        except (serial.SerialException, OSError) as exc:
            raise TransientInstrumentError(f"{self.name}: {request!r}: port failed: {exc}", reconnect=True) from None
        if is_block(raw):
            self._let_late_reply_pass()
            raise InstrumentError(f"{self.name}: {request!r}: the controller answers every command with an error "
                                  "code and a length before the text (TM-8004-C §2), which this profile does not "
                                  "read: set the rig config's protocol_overrides: {acknowledgement: length-prefixed}")
        if not raw.endswith(self._read_terminator):
            self._let_late_reply_pass()
            raise TransientInstrumentError(f"{self.name}: {request!r}: no reply within the timeout")
        # Lines before the last are late replies to earlier requests that arrived with this one.
        last = raw[: -len(self._read_terminator)].split(self._read_terminator)[-1]
        return last.decode(self._encoding, errors="replace").strip()

    def ask_block(self, request: str) -> tuple[int, str]:
        """Send one request and read its response block (protocols/acl_blocks.py): the error code and the text
        (a NUL after it dropped)."""
        self.send(request)
        try:
            raw = self._read_block()
        except (serial.SerialException, OSError) as exc:
            raise TransientInstrumentError(f"{self.name}: {request!r}: port failed: {exc}", reconnect=True) from None
        found = prefix(raw)
        if found is None:
            if raw and not looks_like_prefix(raw):
                self._let_late_reply_pass()
                raise InstrumentError(f"{self.name}: {request!r}: the controller answered {ascii(bytes(raw[:40]))} "
                                      "with no error code and length before it: it does not acknowledge every "
                                      "command (TM-8004-C §2 says GPIB does not); set the rig config's "
                                      "protocol_overrides: {acknowledgement: none}")
            self._let_late_reply_pass()
            raise TransientInstrumentError(f"{self.name}: {request!r}: no reply within the timeout")
        code, length = found
        if len(raw) < PREFIX_BYTES + length:
            self._let_late_reply_pass()
            raise TransientInstrumentError(f"{self.name}: {request!r}: a response cut short ({len(raw)} of "
                                           f"{PREFIX_BYTES + length} bytes within the timeout)")
        text = raw[PREFIX_BYTES:PREFIX_BYTES + length].decode(self._encoding, errors="replace")
        return code, text.rstrip("\0").strip()

    def send(self, request: str) -> None:
        """Send a request: one that has no reply (a SCPI setting), or one whose reply `receive` reads."""
        data = request.encode(self._encoding) + self._write_terminator
        try:
            self._port.reset_input_buffer()  # a late reply to an earlier, timed-out request is stale
            if self._local_device():
                self._write_fd(data)
            else:
                self._port.write(data)
        except (serial.SerialException, OSError) as exc:
            raise TransientInstrumentError(f"{self.name}: {request!r}: port failed: {exc}", reconnect=True) from None

    def close(self) -> None:
        self._port.close()

    def reconnect(self) -> None:
        """Close and open the port again (a USB adapter that dropped off the bus and came back)."""
        timeout_s = self._port.timeout or 1.0
        self._port.close()
        self._port = _open_port(self.name, self._endpoint, self._baudrate, timeout_s)

    def _let_late_reply_pass(self) -> None:
        """After a timeout, wait one more timeout and discard what comes: a reply that was only late must
        not be read as the answer to the next request (a line protocol has no request numbers)."""
        try:
            self._read_line()
            self._port.reset_input_buffer()
        except (serial.SerialException, OSError):
            pass  # the port itself failed: the next request says so

    def _read_line(self) -> bytes:
        """Bytes up to the terminator; stops short at the port's timeout or, for a device that keeps
        talking without ever ending its line, at a deadline of the same length."""
        line = bytearray()
        deadline = time.monotonic() + (self._port.timeout or 0.0)
        read = self._read_fd if self._local_device() else self._read_port
        while not line.endswith(self._read_terminator):
            chunk = read(deadline)
            if not chunk or time.monotonic() > deadline:
                break
            line += chunk
        return bytes(line)

    def _read_block(self) -> bytes:
        """A response block: its prefix, then as many bytes as it says; stops short at the port's timeout. A
        reply that is a line of text instead (no prefix) is returned once its terminator has come."""
        data = bytearray()
        deadline = time.monotonic() + (self._port.timeout or 0.0)
        read = self._read_fd if self._local_device() else self._read_port
        while True:
            found = prefix(bytes(data))
            if found is not None and len(data) >= PREFIX_BYTES + found[1]:
                break
            if found is None and len(data) >= PREFIX_BYTES and not looks_like_prefix(bytes(data)) \
                    and self._read_terminator in data:
                break
            chunk = read(deadline)
            if not chunk or time.monotonic() > deadline:
                break
            data += chunk
        return bytes(data)

    def _local_device(self) -> bool:
        """A plain local device (not a spy:// or other URL's port, whose own read and write do more): read
        and written on its descriptor directly."""
        return type(self._port) is serial.Serial and self._port.is_open

    def _write_fd(self, data: bytes) -> None:
        """All of `data` to a local device within its write timeout: one write where pyserial's costs a select
        and a loop in Python per call."""
        timeout_s = self._port.write_timeout or self._port.timeout or 1.0
        if write_within(self._port.fileno(), data, time.monotonic() + timeout_s):
            raise serial.SerialTimeoutException("write timeout")

    def _read_port(self, deadline: float) -> bytes:
        """What has arrived, waiting up to the port's timeout for the first byte (any pyserial port)."""
        return self._port.read(max(1, self._port.in_waiting))

    def _read_fd(self, deadline: float) -> bytes:
        """What has arrived on a local serial device, waiting until `deadline`: one select and one read,
        where pyserial's read costs four system calls (a fixture of 64 bridges asks ~10⁵ times a campaign)."""
        chunk = read_within(self._port.fileno(), deadline)
        if chunk is None:
            return b""
        if not chunk:
            raise serial.SerialException("device reports readiness to read but returned no data "
                                         "(device disconnected or multiple access on port?)")
        return chunk


def describe_endpoint(endpoint: str) -> str:
    """How messages name a line's endpoint: `tcp host:port` for a pyserial socket URL, else `serial …`."""
    return f"tcp {endpoint.removeprefix('socket://')}" if endpoint.startswith("socket://") else f"serial {endpoint}"


def _open_port(name: str, endpoint: str, baudrate: int, timeout_s: float) -> serial.SerialBase:
    try:
        return serial.serial_for_url(endpoint, baudrate=baudrate, timeout=timeout_s, write_timeout=timeout_s)
    except (serial.SerialException, ValueError) as exc:
        cause = exc.__context__  # pyserial wraps the system's error in its own words around it: say it once
        detail = cause.strerror if isinstance(cause, OSError) and cause.strerror else str(exc)
        raise InstrumentError(f"{name}: cannot open: {detail}") from None
