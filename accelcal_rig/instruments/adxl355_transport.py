"""Ways to reach an ADXL355's registers: a serial bridge speaking a small line protocol, or Linux spidev.

The bridge protocol (docs/instruments.md): one ASCII request per line, one reply per request.
    ?                    → `ADXL355-BRIDGE <version> <free text>`
    R <addr> <count>     → `=<hex bytes>`   read `count` registers from `addr` (hex); FIFO_DATA (0x11)
                                            does not auto-increment, so a burst of it drains the FIFO
    W <addr> <value>     → `=`              write one register (both hex)
    C <count>            → `=<TEMP2 TEMP1>` (version 2) empty the FIFO, then capture the next `count`
                                            samples into the bridge's own memory, draining the FIFO
                                            itself; the reply is the temperature as the capture starts
    G <first>            → `=<hex bytes>`   (version 2) the captured samples from index `first` on, as the
                                            part's FIFO gives them (an ADXL35x: 9 bytes each; an
                                            ICM-42688-P: 16-byte packets); once the capture is complete the reply
                                            ends in `T<TEMP2 TEMP1>`, the temperature as the last sample
                                            came; `!overflow …` if the capture lost samples. The capture
                                            stays until the next `C`, so a lost reply is asked for again
    any failure          → `!<message>`

A version 2 bridge greets with `capture=<samples>`, its buffer and the largest `count`. At high data rates
a host behind USB serial cannot drain a 32-sample FIFO in time (at 4 kHz it fills in 8 ms); the bridge's
firmware can. A version 3 bridge names the part behind it (`part=<name>`, e.g. `part=icm42688p`): `R` and `W`
are register-generic (the bridge frames them for its part's SPI), `C` and `G` exist only where it greets with
`capture=`. A bridge that names no part (versions 1 and 2) has an ADXL355, ADXL357 or ADXL359 behind it. The
temperatures `C` and `G` return are the part's two temperature registers, read as its part table says.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

from accelcal_rig.core.extras import install_hint
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.parts import registry as parts
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.parts.part import Part, SpiFraming

BRIDGE_GREETING = "ADXL355-BRIDGE"
#: The newest bridge protocol version this driver speaks (1: registers; 2: capture; 3: names its part).
PROTOCOL_VERSION = 3
#: Tries of the greeting when a bridge is opened (a board may still be booting, or the line noisy).
GREETING_ATTEMPTS = 3


class RegisterTransport(Protocol):
    endpoint: str

    @property
    def capture_capacity_samples(self) -> int:
        """Samples the transport can capture on its own (0: none; the host drains the FIFO itself)."""

    def read(self, address: int, count: int) -> bytes: ...
    def write(self, address: int, value: int) -> None: ...
    def close(self) -> None: ...


class CaptureOverflow(InstrumentError):
    """A bridge-side capture lost samples (its buffer was not fetched in time)."""


@runtime_checkable
class BlockCapture(Protocol):
    """A transport that captures gap-free blocks itself (a version 2 serial bridge)."""

    def start_capture(self, n_samples: int) -> int:
        """Start capturing; returns the part's raw temperature code as the capture starts."""

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        """(captured FIFO bytes from sample `first` on, raw temperature at the end once it is complete)."""


@runtime_checkable
class PostedRequests(Protocol):
    """A transport whose requests can go out now and their replies be read later: one thread asks every
    bridge first, then reads each reply, and the bridges answer at the same time."""

    def post_read(self, address: int, count: int) -> None: ...
    def receive_read(self, address: int, count: int) -> bytes: ...
    def post_capture(self, n_samples: int) -> None: ...
    def receive_capture(self, n_samples: int) -> int: ...
    def post_fetch(self, first: int) -> None: ...
    def receive_fetch(self, first: int) -> tuple[bytes, int | None]: ...


class SerialBridge:
    """The bridge line protocol over pyserial (a device path or any pyserial URL)."""

    def __init__(self, line: LinePort, endpoint: str) -> None:
        self._line = line
        self.endpoint = endpoint
        self.capture_capacity_samples = 0
        #: The part the bridge says is behind it (version 3), None where it does not say.
        self.part_name: str | None = None
        #: The part whose FIFO samples and temperature registers a capture returns: the one the bridge names
        #: (where this program knows it), else an ADXL355 (versions 1 and 2 have one behind them).
        self._capture_part: Part = ADXL355

    @classmethod
    def open(cls, endpoint: str, baudrate: int = 921600, timeout_s: float = 1.0,
             attempts: int = GREETING_ATTEMPTS, sleep: Callable[[float], None] | None = None) -> SerialBridge:
        """Open and greet: `attempts` tries of the greeting, `sleep` (the campaign clock's) waiting 0.5 s,
        1 s, 2 s … between them (before any event log exists: quietly)."""
        bridge = cls(LinePort.open(endpoint, "sensor bridge", baudrate, timeout_s), f"serial {endpoint}")
        for attempt in range(1, attempts + 1):
            try:
                greeting = bridge._ask("?")
                break
            except TransientInstrumentError:
                if attempt == attempts:
                    bridge.close()
                    raise
                if sleep is not None:
                    sleep(0.5 * 2 ** (attempt - 1))
        if not greeting.startswith(BRIDGE_GREETING):
            bridge.close()
            raise InstrumentError(f"sensor bridge (serial {endpoint}): not an ADXL355 bridge (answers {greeting!r})")
        version = _version(greeting)
        if version is not None and version > PROTOCOL_VERSION:
            bridge.close()
            raise InstrumentError(f"sensor bridge (serial {endpoint}): speaks bridge protocol version {version}, this "
                                  f"driver 1…{PROTOCOL_VERSION} (answers {greeting!r})")
        bridge.capture_capacity_samples = _capture_capacity(greeting)
        bridge.part_name = _greeting_value(greeting, "part") if version is not None and version >= 3 else None
        if bridge.part_name in parts.known_parts():
            bridge._capture_part = parts.part(bridge.part_name)
        return bridge

    def read(self, address: int, count: int) -> bytes:
        self.post_read(address, count)
        return self.receive_read(address, count)

    def post_read(self, address: int, count: int) -> None:
        """Send a register read whose reply `receive_read` collects (several bridges read at once)."""
        self._line.send(f"R {address:02X} {count}")

    def receive_read(self, address: int, count: int) -> bytes:
        request = f"R {address:02X} {count}"
        reply = self._refusal_raised(request, self._line.receive(request))
        try:
            data = bytes.fromhex(reply[1:])
        except ValueError:
            raise TransientInstrumentError(f"sensor bridge ({self.endpoint}): garbled reply {reply[:40]!r}") from None
        if not reply.startswith("=") or len(data) != count:
            raise TransientInstrumentError(f"sensor bridge ({self.endpoint}): read of {count} bytes at 0x{address:02X} "
                                  f"answered {reply[:40]!r}")
        return data

    def write(self, address: int, value: int) -> None:
        reply = self._ask(f"W {address:02X} {value:02X}")
        if reply != "=":
            raise TransientInstrumentError(f"sensor bridge ({self.endpoint}): write 0x{value:02X} to 0x{address:02X} "
                                  f"answered {reply[:40]!r}")

    def start_capture(self, n_samples: int) -> int:
        self.post_capture(n_samples)
        return self.receive_capture(n_samples)

    def post_capture(self, n_samples: int) -> None:
        """Send `C` (its reply collected by `receive_capture`): several bridges start at once."""
        self._line.send(f"C {n_samples}")

    def receive_capture(self, n_samples: int) -> int:
        request = f"C {n_samples}"
        reply = self._refusal_raised(request, self._line.receive(request))
        temperature = _raw_temperature(reply[1:], self._capture_part) if reply.startswith("=") else None
        if temperature is None:
            raise TransientInstrumentError(f"sensor bridge ({self.endpoint}): capture of {n_samples} answered "
                                           f"{reply[:40]!r}")
        return temperature

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        self.post_fetch(first)
        return self.receive_fetch(first)

    def post_fetch(self, first: int) -> None:
        """Send `G` (its reply collected by `receive_fetch`): several bridges are fetched at once."""
        self._line.send(f"G {first}")

    def receive_fetch(self, first: int) -> tuple[bytes, int | None]:
        request = f"G {first}"
        reply = self._line.receive(request)
        if reply.startswith("!overflow"):
            raise CaptureOverflow(f"sensor bridge ({self.endpoint}): {reply[1:]}")
        reply = self._refusal_raised(request, reply)
        samples, end_marker, temperature_hex = reply[1:].partition("T")
        temperature = _raw_temperature(temperature_hex, self._capture_part) if end_marker else None
        try:
            data = bytes.fromhex(samples)
        except ValueError:
            data = b"?"
        if not reply.startswith("=") or len(data) % self._capture_part.fifo_sample_bytes \
                or (end_marker and temperature is None):
            raise TransientInstrumentError(f"sensor bridge ({self.endpoint}): garbled capture {reply[:40]!r}")
        return data, temperature

    def close(self) -> None:
        self._line.close()

    def reconnect(self) -> None:
        self._line.reconnect()

    def _ask(self, request: str) -> str:
        return self._refusal_raised(request, self._line.ask(request))

    def _refusal_raised(self, request: str, reply: str) -> str:
        if reply.startswith("!"):
            raise InstrumentError(f"sensor bridge ({self.endpoint}): {request!r} refused: {reply[1:]}")
        return reply


def _raw_temperature(hex_digits: str, part: Part) -> int | None:
    """The part's two temperature registers as 4 hex digits (an ADXL355's TEMP2, TEMP1) → its raw temperature
    code; None if malformed."""
    try:
        high, low = bytes.fromhex(hex_digits)
    except ValueError:
        return None
    return part.temperature.from_registers(high, low)


def _version(greeting: str) -> int | None:
    """`ADXL355-BRIDGE 3 …` → 3; None where the greeting gives no version number."""
    words = greeting.split()
    return int(words[1]) if len(words) >= 2 and words[1].isdigit() else None


def _greeting_value(greeting: str, key: str) -> str | None:
    """The value of `key=value` among the greeting's words after the version (`capture`, `part`)."""
    for word in greeting.split()[2:]:
        name, sep, value = word.partition("=")
        if sep and name == key:
            return value
    return None


def _capture_capacity(greeting: str) -> int:
    """`ADXL355-BRIDGE 2 capture=4096 …` → 4096; a version 1 bridge, or one that does not say, captures nothing."""
    version = _version(greeting)
    value = _greeting_value(greeting, "capture")
    if version is None or version < 2 or value is None:
        return 0
    return int(value) if value.isdigit() else 0


class SpidevBus:
    """Linux spidev (optional extra `spidev`): the SPI mode and the command byte framed as the part says (an
    ADXL355: mode 0, (addr << 1) | 1 reads, addr << 1 writes; an ICM-42688-P: mode 0, addr | 0x80 reads, addr
    writes; an LIS3MDL: mode 3, addr | 0x80 reads, 0x40 more for a burst). The host is on the SPI bus itself
    and reads in time: no capture of its own."""

    capture_capacity_samples = 0

    def __init__(self, device: Any, endpoint: str, framing: SpiFraming = ADXL355.spi) -> None:
        self._device = device  # a spidev.SpiDev (untyped)
        self.endpoint = endpoint
        self._framing = framing

    @classmethod
    def open(cls, bus: int, chip_select: int, speed_hz: int = 5_000_000,
             framing: SpiFraming = ADXL355.spi) -> SpidevBus:
        try:
            import spidev  # type: ignore[import-not-found]
        except ImportError:
            raise InstrumentError(f"spidev is not installed: {install_hint('spi')}") from None
        device = spidev.SpiDev()
        try:
            device.open(bus, chip_select)
        except OSError as exc:
            raise InstrumentError(f"sensor (spidev {bus}.{chip_select}): cannot open: {exc}") from None
        device.mode = framing.mode
        device.max_speed_hz = speed_hz
        return cls(device, f"spidev {bus}.{chip_select}", framing)

    def read(self, address: int, count: int) -> bytes:
        return bytes(self._device.xfer2([self._framing.read_command(address, count)] + [0] * count)[1:])

    def write(self, address: int, value: int) -> None:
        self._device.xfer2([self._framing.write_command(address), value])

    def close(self) -> None:
        self._device.close()
