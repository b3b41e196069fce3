"""Every request the makers' clients send (issue 43), swept: each public client, unchanged, against the
simulator of its controller, every public member of its class called (enumerated with inspect and its
arguments generated from its signature and docstring, in tests/protocols/client_sweep_child.py), with a
recording proxy between the client and the simulator, so that what was sent and what came back is the bytes on
the wire, request by request.

A client whose code cannot be installed (ESPEC's F4T SCPI library, the ACUTROL clients) is replayed from its
requests as data (tests/protocols/client_requests.py), through the same proxy, the way that client reads the
replies (a line; or, the AcutronicRobotics client, one recv() with an 8-byte prefix cut off).

Each call ends as: every request answered and the client reading it (`as documented`, or one of the refusals or
silences the maker documents: DOCUMENTED), a deviation (a request refused or unanswered, or a reply the client
could not read), a client limitation on record (CLIENT_LIMITS), or not exercised (with the reason). The survey
(`python -m tests.protocols.client_sweep --markdown FILE [--json FILE]`) writes the counts and every deviation;
tests/protocols/test_client_sweep.py runs the sweep as a prototype test that records and does not fail on them.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import os
import queue
import re
import select
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, ChamberLineProtocol, line_protocol
from accelcal_rig.protocols.chamber_registers import register_map
from accelcal_rig.protocols.turntable_line import ACUTROL3000, turntable_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.chamber_server import SimulatedChamberServer
from accelcal_rig.sim.f4t_scpi_extras import serves as f4t_serves
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.register_panels import panel_for
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG
from tests.protocols.client_requests import DATA_CLIENTS, DataClient, Expect
from tests.protocols.maker_requests import NOT_SIMULATED as CHAMBER_NOT_SIMULATED
from tests.protocols.maker_requests import REFUSALS as LINE_REFUSALS
from tests.protocols.maker_requests import UNDOCUMENTED_SPELLINGS
from tests.protocols.modbus_requests import not_simulated as modbus_not_simulated
from tests.protocols.turntable_requests import NOT_SIMULATED as TURNTABLE_NOT_SIMULATED

CHILD = Path(__file__).with_name("client_sweep_child.py")
#: After the client's call returns, the wire is taken as settled once it has been quiet this long.
QUIET_S = 0.02


# ---------------------------------------------------------------------- the recording proxy
@dataclass
class Chunk:
    direction: str  # "request" (client to controller) or "reply"
    data: bytes
    connection: int


class _Upstream:
    """The simulator's end of one proxied connection: a TCP socket or a pty."""

    def __init__(self, endpoint: str, kind: str) -> None:
        self.kind = kind
        if kind == "tcp":
            host, port = endpoint.rsplit(":", 1)
            self.sock: socket.socket | None = socket.create_connection((host, int(port)), timeout=5)
            self.fd = self.sock.fileno()
        else:
            self.sock = None
            self.fd = os.open(endpoint, os.O_RDWR | os.O_NOCTTY)

    def read(self) -> bytes:
        try:
            return self.sock.recv(65536) if self.sock is not None else os.read(self.fd, 65536)
        except OSError:
            return b""

    def write(self, data: bytes) -> None:
        if self.sock is not None:
            self.sock.sendall(data)
            return
        view = memoryview(data)
        while view:
            view = view[os.write(self.fd, view):]

    def close(self) -> None:
        if self.sock is not None:
            self.sock.close()
        else:
            os.close(self.fd)


class RecordingProxy:
    """A TCP listener on loopback in front of a simulator (its TCP endpoint, or its pty path): every byte each
    way is forwarded and recorded in order."""

    def __init__(self, endpoint: str, kind: str = "tcp") -> None:
        self._endpoint, self._kind = endpoint, kind
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self.chunks: list[Chunk] = []
        self._lock = threading.Lock()
        self._last = time.monotonic()
        self._connections = 0
        self._open: list[socket.socket] = []
        self._stopped = False
        threading.Thread(target=self._accept, name="recording-proxy", daemon=True).start()

    def _accept(self) -> None:
        while not self._stopped:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            self._connections += 1
            self._open.append(client)
            upstream = _Upstream(self._endpoint, self._kind)
            threading.Thread(target=self._pump, args=(client, upstream, self._connections), daemon=True).start()

    def _record(self, direction: str, data: bytes, connection: int) -> None:
        with self._lock:
            self.chunks.append(Chunk(direction, data, connection))
            self._last = time.monotonic()

    def _pump(self, client: socket.socket, upstream: _Upstream, connection: int) -> None:
        try:
            while True:
                readable, _, _ = select.select([client.fileno(), upstream.fd], [], [], 0.5)
                if self._stopped:
                    return
                if client.fileno() in readable:
                    data = client.recv(65536)
                    if not data:
                        return
                    self._record("request", data, connection)
                    upstream.write(data)
                if upstream.fd in readable:
                    data = upstream.read()
                    if not data:
                        return
                    self._record("reply", data, connection)
                    client.sendall(data)
        except OSError:
            return
        finally:
            with contextlib.suppress(OSError):
                client.close()
            with contextlib.suppress(OSError):
                upstream.close()

    def mark(self) -> int:
        with self._lock:
            return len(self.chunks)

    def since(self, mark: int) -> list[Chunk]:
        with self._lock:
            return list(self.chunks[mark:])

    def settle(self, quiet_s: float = QUIET_S, limit_s: float = 2.0) -> None:
        """Wait until nothing has crossed for `quiet_s` (a reply on its way is recorded before it is read); a
        longer `quiet_s` (a client that does not read its replies) counts from now at the earliest, so that a
        request still on its way through the proxy is recorded too."""
        start = time.monotonic()
        end = start + limit_s
        while time.monotonic() < end:
            with self._lock:
                idle = time.monotonic() - (self._last if quiet_s <= QUIET_S else max(self._last, start))
            if idle >= quiet_s:
                return
            time.sleep(quiet_s - idle)

    def close(self) -> None:
        self._stopped = True
        self._listener.close()
        for client in self._open:
            with contextlib.suppress(OSError):
                client.close()


# ---------------------------------------------------------------------- what was recorded
@dataclass
class Exchange:
    request: str  # the bytes sent, as Python's repr of bytes (terminators visible)
    reply: str  # the bytes that came back before the next request ('' none)
    simulator: str  # answered | refused | silence
    detail: str = ""  # the refusal's text, the Modbus exception
    text: str = ""  # the request as read: a line's text, or a Modbus request's function, register and values
    reply_text: str = ""  # the reply as read
    documented: str = ""  # a request-list client's: the answer its maker documents (and where)
    problem: str = ""  # a request-list client's: how the reply differs from the documented one ('' none)


@dataclass
class CallRecord:
    member: str
    text: str  # the call as made (generated arguments), or the request list's method
    derived: str = ""  # how its arguments were generated
    outcome: str = ""  # returned | raised | deadline | not-called | constructed
    value: str = ""  # what it returned (repr), or the exception
    frames: list[str] = field(default_factory=list)  # where in the client's source an exception passed
    exchanges: list[Exchange] = field(default_factory=list)
    verdict: str = ""  # as-documented | deviation | client-limit | sends-nothing | not-exercised
    why: str = ""  # the documented entry or client limit it matched, or what deviates


@dataclass
class MemberRecord:
    name: str
    kind: str  # method | property | inherited | attribute | class | request-list
    defined_in: str
    calls: list[int] = field(default_factory=list)  # indices into ClientSweep.calls
    not_called: str | None = None


@dataclass
class ClientSweep:
    client: str  # the client's name in CLIENTS / DATA_CLIENTS
    profile: str  # the simulator's profile
    source: str  # where the client comes from (PyPI version, or repository@commit)
    transport: str  # how the client reached the simulator (and any transport construction replaced)
    members: list[MemberRecord] = field(default_factory=list)
    calls: list[CallRecord] = field(default_factory=list)
    problem: str | None = None  # the sweep could not run (no interpreter, the client not installed)
    seconds: float = 0.0


#: Line profiles whose controller answers every request with exactly one line (ESPEC: `OK:<command>` or
#: `NA:<error>` to every command, EHS manual §1.3 as ChamberConnectLibrary's especinteract.py reads it). A client
#: that writes several requests before it reads (py-lab-hal's send()) gets their replies together: they are
#: given back to its requests one line each, in order.
ONE_REPLY_EACH = frozenset({"espec-p300"})


def _one_line_each(pairs: list[list[bytes]]) -> list[list[bytes]]:
    """Where a reply of k lines follows k-1 requests that got none, each takes one line, in order."""
    for index, (_, reply) in enumerate(pairs):
        lines = re.findall(rb"[^\r\n]*\r?\n", reply)
        if len(lines) < 2 or b"".join(lines) != reply:
            continue
        start = index
        while start > index - len(lines) + 1 and start > 0 and not pairs[start - 1][1]:
            start -= 1
        if index - start + 1 == len(lines):
            for offset, line in enumerate(lines):
                pairs[start + offset][1] = line
    return pairs


def exchanges(chunks: list[Chunk], error: re.Pattern[str] | None, modbus: bool,
              one_reply_each: bool = False) -> list[Exchange]:
    """The recorded bytes as request/reply pairs: each request a client sent (a line, with its terminator; a
    Modbus frame: each run of bytes), and what came back before it sent again on that connection."""
    pairs: list[list[bytes]] = []
    last: tuple[str, int] | None = None
    for chunk in chunks:
        if chunk.direction == "request" and (last is None or last != ("request", chunk.connection)):
            pairs.append([chunk.data, b""])
        elif chunk.direction == "request":
            pairs[-1][0] += chunk.data
        elif pairs:
            pairs[-1][1] += chunk.data
        else:
            pairs.append([b"", chunk.data])
        last = (chunk.direction, chunk.connection)
    if not modbus:  # lines sent one after another without a reply between them are requests of their own
        split = []
        for request, reply in pairs:
            lines = re.findall(rb"[^\r\n]*(?:\r\n|\r|\n)|[^\r\n]+$", request) or [request]
            split += [[line, b""] for line in lines[:-1]] + [[lines[-1], reply]]
        pairs = _one_line_each(split) if one_reply_each else split
    found = []
    for request, reply in pairs:
        simulator, detail = "answered", ""
        if not reply:
            simulator = "silence"
        elif modbus and len(reply) >= 9 and reply[7] & 0x80:
            simulator, detail = "refused", f"Modbus exception {reply[8]}"
        elif error is not None:
            text = reply.decode("latin-1").strip()
            if error.search(text):
                simulator, detail = "refused", text
        if modbus:
            text, reply_text = modbus_request(request), modbus_reply(reply)
        else:
            text, reply_text = request.decode("latin-1").strip(), reply.decode("latin-1").strip()
        found.append(Exchange(repr(request), repr(reply), simulator, detail, text, reply_text))
    return found


def modbus_request(frame: bytes) -> str:
    """A Modbus TCP request as read: `read holding 300 x1`, `write 2000 = 1`, `write 2782.. = [..]` (zero-based)."""
    if len(frame) < 12:
        return repr(frame)
    function, address = frame[7], int.from_bytes(frame[8:10], "big")
    if function in (3, 4):
        kind = "holding" if function == 3 else "input"
        return f"read {kind} {address} x{int.from_bytes(frame[10:12], 'big')}"
    if function == 6:
        return f"write {address} = {int.from_bytes(frame[10:12], 'big')}"
    if function == 16:
        count = int.from_bytes(frame[10:12], "big")
        words = [int.from_bytes(frame[13 + 2 * i:15 + 2 * i], "big") for i in range(count)]
        return f"write {address} x{count} = {words}"
    return f"function {function} at {address}: {frame[7:]!r}"


def modbus_reply(frame: bytes) -> str:
    if len(frame) < 9:
        return repr(frame)
    function = frame[7]
    if function & 0x80:
        return f"exception {frame[8]}"
    if function in (3, 4):
        count = frame[8] // 2
        return str([int.from_bytes(frame[9 + 2 * i:11 + 2 * i], "big") for i in range(count)])
    return "written"


# ---------------------------------------------------------------------- the simulators
@contextlib.contextmanager
def simulator(kind: str, profile: str, options: dict[str, object]) -> Iterator[tuple[str, str]]:
    """(endpoint, transport kind) of a fresh simulated controller: a line chamber (TCP), a Modbus chamber (TCP)
    or the ACUTROL3000 turntable (pty)."""
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server: SimulatedLineChamberServer | SimulatedChamberServer | SimulatedTurntableServer
    if kind == "line":
        fields = ChamberLineProtocol.model_fields  # a profile's own fields (an RS-485 address) configure the profile
        overrides = {key: value for key, value in options.items() if key in fields}
        rest = {key: value for key, value in options.items() if key not in fields}
        server = SimulatedLineChamberServer(lab, line_protocol(profile, overrides), "tcp", **rest)  # type: ignore[arg-type]
    elif kind == "modbus":
        server = SimulatedChamberServer(lab, register_map(profile), panel=panel_for(profile, register_map(profile)))
    else:
        server = SimulatedTurntableServer(lab, turntable_protocol("acutrol3000", options) if options else ACUTROL3000)
    server.start()
    try:
        yield server.endpoint, "pty" if kind == "turntable" else "tcp"
    finally:
        server.stop()


def error_pattern(kind: str, profile: str) -> re.Pattern[str] | None:
    if kind == "line":
        text = LINE_PROFILES[profile].error_pattern
        return None if text == "(?!)" else re.compile(text)
    if kind == "turntable":
        return re.compile(ACUTROL3000.error_pattern)
    return None


# ---------------------------------------------------------------------- installable clients
@dataclass(frozen=True)
class ClientSpec:
    """A client installed here, run unchanged in a process of its own (tests/protocols/client_sweep_child.py)."""

    name: str
    distribution: str  # the installed distribution (its version goes into the record)
    own_prefix: str  # a member defined in a module under this prefix is the client's own
    factory: str  # how client_sweep_child.py constructs it (plain, basil, chamberconnect)
    construct: dict[str, object]  # what that factory takes ($host, $port filled in)
    kind: str  # the simulator: line or modbus
    profile: str
    transport: str  # what reaches the simulator, and what of the transport's construction is replaced
    python: str = "3"  # "2.7": the client is Python 2 code
    sim_options: dict[str, object] = field(default_factory=dict)
    table: dict[str, object] = field(default_factory=dict)  # values by parameter name, only where not derivable
    deadline_s: float = 4.0  # a call still running then is ended (its process, and a new one goes on)
    #: how long the wire must be quiet after a call before its record closes: longer for a client that sends
    #: settings without reading their replies (the reply then comes after the call has returned)
    quiet_s: float = QUIET_S
    not_installed: str = ""  # why it may not be installed here (the sweep skips it then, saying so)


#: Parameters of ChamberConnectLibrary's members that neither their signatures nor their docstrings type.
_CCL_TABLE: dict[str, object] = {
    "message": {"$not_callable": "a raw request the caller writes (interact): it sends what it is given"},
    "command": {"$not_callable": "a raw request the caller writes (raw): it sends what it is given"},
    "arg": {"$not_callable": "parses a reply text its caller passes: sends nothing"},
    "program": {"$not_callable": "takes a whole program in read_prgm's format (undocumented beyond that)"},
    "prgm": {"$not_callable": "takes a whole program in the controller's own format (get_prgm's; undocumented)"},
    "func": {"$not_callable": "a cache in front of another member's call: sends what that member sends"},
    "identifier": "Temperature",  # get_loop: 'the name of the loop' (the Espec class names loop 1 so)
    "dow": "MON",  # write_date's day of the week: P300 manual spelling as the library writes it
    "address": "192.168.0.10", "mask": "255.255.255.0", "gateway": "192.168.0.1",
    "relays": [True, False],
    "mode": "manual",  # encode_refrig / write_set: "off", "manual" or "auto" (write_set's docstring)
    "setpoint": 20,  # encode_refrig: 20, 50 or 100 (write_set's docstring)
    "value": "Auto",  # a loop mode given as text: get_loop's docstring names 'Off', 'Auto', 'Manual'
    "num": 1,
    "pgmnum": 1, "pgmstep": 1,  # read_prgm, write_prgm_run (its docstring names 'prgmstep')
    "op_range": {"max": 100.0, "min": -40.0},  # write_ptc: its docstring names it 'range'
    "pid_p": 1.0, "pid_i": 1.0, "pid_filter": 0.0,  # write_ptc: its docstring names them 'p', 'i', 'filter'
}

_PYMEASURE_TABLE: dict[str, object] = {
    "command": {"$not_callable": "the transport primitive (write, with its 1 s pause): sends what it is given"}}
_BASIL_TABLE: dict[str, object] = {
    "cmd": {"$not_callable": "the transport primitive (query): sends what it is given"},
    "value": True,  # set_compressed_air(value) and the like: int(value) is the output's state, 0 or 1
    "target": 25.0,  # set_temperature(target): a temperature in °C (str(target) is sent)
}

_SYNDESI_TABLE: dict[str, object] = {
    "program": 1,  # a program number (its docstring: int; PRGM DATA?,RAM:<program>)
    "step": 1,
    "temperature": 25.0,  # set_temperature: 'float or str' ('OFF' the str it documents)
    "humidity": 50,  # set_humidity: 'int or str'
}
_PYLABHAL_TABLE: dict[str, object] = {
    "mode": True,  # enable_ramp(mode) / enable_power(mode: bool): on or off
    "temper": 25.0,  # set_set_point: 'temperature of set point in C' (float)
    "ramp_rate": 1.5,  # set_ramp_rate: 'Ramp rate in C per minute' (float)
    "num_profile": 1, "num_porfile": 1,  # run_profile / delete_profile: a profile number
    "run": True,
    "name": "P1", "number": 1, "step": 1,  # create_profile (sends nothing in either class)
}

CLIENTS: tuple[ClientSpec, ...] = (
    ClientSpec("ChamberConnectLibrary P300", "chamberconnectlibrary", "chamberconnectlibrary", "chamberconnect",
               {"module": "chamberconnectlibrary.p300", "class": "P300", "kwargs": {"interface": "TCP", "host": "$host"},
                "transport": "EspecTCP", "transport_module": "chamberconnectlibrary.especinteract",
                "patch_module": "chamberconnectlibrary.p300"},
               "line", "espec-p300", "TCP through the proxy; P300 builds EspecTCP without a port (10001 fixed): the "
               "name p300.py imported is given the proxy's port", python="2.7", table=_CCL_TABLE),
    ClientSpec("ChamberConnectLibrary Espec (P300)", "chamberconnectlibrary", "chamberconnectlibrary", "chamberconnect",
               {"module": "chamberconnectlibrary.espec", "class": "Espec",
                "kwargs": {"interface": "TCP", "host": "$host", "ctlr_type": "P300", "loops": 2},
                "transport": "EspecTCP", "transport_module": "chamberconnectlibrary.especinteract",
                "patch_module": "chamberconnectlibrary.p300"},
               "line", "espec-p300", "as P300 (the Espec controller class drives a P300 object); loops=2: "
               "temperature and humidity, as the simulated chamber", python="2.7", table=_CCL_TABLE),
    ClientSpec("ChamberConnectLibrary WatlowF4", "chamberconnectlibrary", "chamberconnectlibrary", "chamberconnect",
               {"module": "chamberconnectlibrary.watlowf4", "class": "WatlowF4",
                "kwargs": {"interface": "TCP", "host": "$host"},
                "transport": "ModbusTCP", "transport_module": "chamberconnectlibrary.modbus",
                "patch_module": "chamberconnectlibrary.watlowf4"},
               "modbus", "watlow-f4", "Modbus TCP through the proxy; WatlowF4.connect builds ModbusTCP without a port "
               "(502 fixed): the name watlowf4.py imported is given the proxy's port", python="2.7", table=_CCL_TABLE),
    ClientSpec("ChamberConnectLibrary WatlowF4T", "chamberconnectlibrary", "chamberconnectlibrary", "chamberconnect",
               {"module": "chamberconnectlibrary.watlowf4t", "class": "WatlowF4T",
                "kwargs": {"interface": "TCP", "host": "$host"},
                "transport": "ModbusTCP", "transport_module": "chamberconnectlibrary.modbus",
                "patch_module": "chamberconnectlibrary.watlowf4t"},
               "modbus", "watlow-f4t", "Modbus TCP through the proxy; as WatlowF4 (watlowf4t.py's ModbusTCP given the "
               "proxy's port)", python="2.7", table=_CCL_TABLE),
    *(ClientSpec(f"PyMeasure Thermotron3800{suffix}", "pymeasure", "pymeasure.instruments.thermotron", "plain",
                 {"module": "pymeasure.instruments.thermotron", "class": "Thermotron3800",
                  "kwargs": {"adapter": "TCPIP::$host::$port::SOCKET", "visa_library": "@py", "timeout": 1000,
                             **terminations}},
                 "line", "thermotron-8800", f"PyVISA (pyvisa-py) TCPIP SOCKET through the proxy; {how}; a 1 s VISA "
                 "timeout", table=_PYMEASURE_TABLE, deadline_s=6.0)
      for suffix, terminations, how in (
          ("", {"write_termination": "\r", "read_termination": "\r\n"}, "CR out, CR LF in (the 8800's, as "
           "test_public_clients.py configures it)"),
          (", PyVISA's terminations", {}, "no terminations given: PyVISA's CR LF out, no read termination"),
          (", LF out", {"write_termination": "\n", "read_termination": "\r\n"}, "LF out, CR LF in"))),
    ClientSpec("espec-pr3j", "espec-pr3j", "espec_pr3j", "plain",
               {"module": "espec_pr3j", "class": "EspecPr3j",
                "kwargs": {"resource_path": "TCPIP0::$host::$port::SOCKET", "resource_manager": {"$pyvisa_rm": "@py"},
                           "communication_timeout": 1000}},
               "line", "espec-p300", "PyVISA (pyvisa-py) TCPIP SOCKET through the proxy (its resource_path "
               "argument); its own CR LF terminations; a 1 s timeout", deadline_s=3.0),
    ClientSpec("basil weissLabEvent", "basil_daq", "basil.HL.weiss_labevent", "basil",
               {"driver": "weiss_labevent",
                "transfer_init": {"address": "$host", "port": "$port", "write_termination": "\r",
                                  "read_termination": "\r\n", "encoding": "ascii"}},
               "line", "simserv", "basil's Socket transfer layer through the proxy, SIMSERV's CR / CR LF (a basil "
               "user's configuration)", sim_options={"identity": "LabEvent T/210/70/5"}, table=_BASIL_TABLE,
               deadline_s=2.0),
    ClientSpec("syndesi-drivers SH242", "syndesi-drivers", "syndesi_drivers", "syndesi",
               {"module": "syndesi_drivers.ovens.espec_sh242", "class": "SH242",
                "adapter": {"address": "$host", "port": "$port", "timeout": 1.0}},
               "line", "espec-p300", "syndesi's IP adapter (TCP) through the proxy, built as a syndesi user does with "
               "the proxy's address and port (the driver sets its 57732 only where no port is given); its own "
               "Delimited CR LF; a 1 s timeout", table=_SYNDESI_TABLE, deadline_s=3.0),
    *(ClientSpec(f"py-lab-hal {cls}", "py-lab-hal", "py_lab_hal", "pylabhal",
                 {"module": f"py_lab_hal.instrument.temp_chamber.{module}", "class": cls, "model": model,
                  "terminator": terminator, "timeout": {"recv": 1}},
                 "line", profile, "py-lab-hal's own socket interface (cominterface/socket.py) through the proxy, "
                 f"built by its PyLabHALBuilder with the proxy's address and port; {how}; a 1 s receive timeout; "
                 "InstrumentConfig's defaults (reset, clear, idn: *RST, *CLS, *IDN? at construction)",
                 table=_PYLABHAL_TABLE, deadline_s=deadline, quiet_s=0.3,
                 not_installed="not in the test extra: py-lab-hal 2.5.20241201 pins PyVISA~=1.14.1, grpcio~=1.62.0 "
                 "and requests~=2.32.3 and pulls monsoon and libusb; install it by hand (pip install --no-deps "
                 "py-lab-hal==2.5.20241201 dataclasses-json) to sweep it")
      for module, cls, model, profile, terminator, how, deadline in (
          ("pu3j", "Pu3j", "TempChamber.PU3J", "espec-p300", {"write": "\r\n", "read": "\r\n"}, "CR LF each way (the "
           "P300's)", 3.0),
          ("testequity_107", "Testequity107", "TempChamber.TESTEQUITY_107", "watlow-f4t-scpi", {"write": "\n", "read": "\n"},
           "LF each way (the F4T's)", 3.5))),
)


def _python27() -> str | None:
    """A Python 2.7 interpreter: $ACCELCAL_PYTHON27, python2.7 on PATH, or a pyenv one."""
    candidates = [os.environ.get("ACCELCAL_PYTHON27", ""), shutil.which("python2.7") or ""]
    candidates += sorted(str(p) for p in Path.home().glob(".pyenv/versions/2.7*/bin/python2.7"))
    for candidate in filter(None, candidates):
        with contextlib.suppress(OSError, subprocess.SubprocessError):
            result = subprocess.run([candidate, "-c", "import sys; print(sys.version_info[0])"], capture_output=True,
                                    text=True, timeout=10, check=False)
            if result.stdout.strip() == "2":
                return candidate
    return None


def _python2_path(spec: ClientSpec, folder: Path) -> str:
    """A folder for Python 2.7's path with the client's package and pyserial as installed here (pure Python)."""
    for package in (spec.own_prefix.split(".")[0], "serial"):
        found = importlib.util.find_spec(package)
        assert found is not None and found.submodule_search_locations, package
        os.symlink(list(found.submodule_search_locations)[0], folder / package)
    return str(folder)


def _version(distribution: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return f"{distribution} {version(distribution)} (installed)"
    except PackageNotFoundError:
        return f"{distribution} (not installed)"


class _Child:
    """One process of client_sweep_child.py: construct, plan, then call by call."""

    def __init__(self, command: list[str], env: dict[str, str], spec_line: str) -> None:
        self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=subprocess.DEVNULL, env=env, text=True, bufsize=1)
        self.messages: queue.Queue[dict[str, object] | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self.send(spec_line)

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            if line.startswith("@@SWEEP "):
                self.messages.put(json.loads(line[len("@@SWEEP "):]))
        self.messages.put(None)

    def send(self, line: str) -> None:
        assert self.process.stdin is not None
        with contextlib.suppress(OSError):
            self.process.stdin.write(line + "\n")
            self.process.stdin.flush()

    def next(self, deadline_s: float) -> dict[str, object] | None:
        """The next message; None: the process ended or the deadline passed."""
        try:
            return self.messages.get(timeout=deadline_s)
        except queue.Empty:
            return None

    def end(self) -> None:
        self.send("exit")
        try:
            self.process.wait(timeout=2)
        except subprocess.TimeoutExpired:
            self.process.kill()  # this process started it; ended by its own handle
            self.process.wait()


def sweep_client(spec: ClientSpec) -> ClientSweep:
    """Run one installed client's every public member against its simulator, recording the wire."""
    started = time.monotonic()
    record = ClientSweep(spec.name, spec.profile, _version(spec.distribution), spec.transport)
    if importlib.util.find_spec(spec.own_prefix.split(".")[0]) is None:
        record.problem = f"{spec.distribution} is not installed" + (f": {spec.not_installed}" if spec.not_installed
                                                                      else "")
        return record
    interpreter = sys.executable
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONUNBUFFERED": "1"}
    with tempfile.TemporaryDirectory(prefix="client-sweep-") as folder:
        if spec.python == "2.7":
            found = _python27()
            if found is None:
                record.problem = "the client is Python 2.7 code (its README: python 2.7.x; print statements) and no " \
                                 "Python 2.7 interpreter was found (set ACCELCAL_PYTHON27)"
                return record
            interpreter = found
            env.pop("PYTHONHOME", None)
            env["PYTHONPATH"] = _python2_path(spec, Path(folder))
        error = error_pattern(spec.kind, spec.profile)
        with simulator(spec.kind, spec.profile, spec.sim_options) as (endpoint, kind):
            proxy = RecordingProxy(endpoint, kind)
            try:
                spec_line = json.dumps({"factory": spec.factory, "own_prefix": spec.own_prefix, "host": "127.0.0.1",
                                        "port": proxy.port, "table": spec.table, **spec.construct})
                _drive(spec, record, proxy, [interpreter, str(CHILD)], env, spec_line, error)
            finally:
                proxy.close()
    classify(record)
    record.seconds = round(time.monotonic() - started, 2)
    return record


def _drive(spec: ClientSpec, record: ClientSweep, proxy: RecordingProxy, command: list[str], env: dict[str, str],
           spec_line: str, error: re.Pattern[str] | None) -> None:
    """Construct, plan, call by call; a call past its deadline ends the process and a new one goes on from the
    next call (constructing again: recorded as another construction)."""
    modbus = spec.kind == "modbus"
    each = spec.profile in ONE_REPLY_EACH
    planned: list[CallRecord] = []
    constructions: list[CallRecord] = []
    index, total = 0, None
    try:
        while total is None or index < total:
            mark = proxy.mark()
            child = _Child(command, env, spec_line)
            try:
                constructed = child.next(spec.deadline_s + 10)
                proxy.settle(spec.quiet_s)
                init = CallRecord("__init__", "construction" + (" (again, after a call's deadline)" if constructions
                                                                else ""), exchanges=exchanges(proxy.since(mark), error,
                                                                                              modbus, each))
                constructions.append(init)
                if constructed is None or not constructed.get("ok"):
                    init.outcome = "raised"
                    init.value = str((constructed or {}).get("error", "no answer from the client's process"))
                    init.frames = list((constructed or {}).get("frames", []))  # type: ignore[call-overload]
                    record.problem = f"construction failed: {init.value}"
                    return
                init.outcome, init.value = "constructed", str(constructed.get("class"))
                plan = child.next(30)
                assert plan is not None and plan.get("event") == "plan", plan
                calls = plan["calls"]
                assert isinstance(calls, list)
                if total is None:
                    total = len(calls)
                    members = plan["members"]
                    assert isinstance(members, list)
                    for member in members:
                        record.members.append(MemberRecord(member["name"], member["kind"], member["defined_in"],
                                                           list(member["calls"]), member.get("not_called")))
                    planned = [CallRecord(c["member"], c["text"], c["derived"]) for c in calls]
                assert len(calls) == total, "the plan changed between two processes"
                while index < total:
                    mark = proxy.mark()
                    child.send(f"call {index}")
                    result = child.next(spec.deadline_s)
                    proxy.settle(spec.quiet_s)
                    call = planned[index]
                    call.exchanges = exchanges(proxy.since(mark), error, modbus, each)
                    index += 1
                    if result is None:
                        call.outcome = "deadline"
                        call.value = f"still running after {spec.deadline_s} s: its process was ended"
                        break
                    call.outcome = str(result["outcome"])
                    call.value = str(result.get("value") or result.get("error") or "")
                    call.frames = list(result.get("frames", []))  # type: ignore[call-overload]
            finally:
                child.end()
    finally:
        offset = len(planned)
        record.calls = planned + constructions
        record.members.insert(0, MemberRecord("__init__", "construction", str(spec.construct.get("class", spec.factory)),
                                              list(range(offset, offset + len(constructions)))))


# ---------------------------------------------------------------------- request lists replayed
def sweep_data_client(client: DataClient) -> ClientSweep:
    """A client that cannot be installed, replayed from its request lists (client_requests.py)."""
    started = time.monotonic()
    record = ClientSweep(client.name, client.profile, client.source, client.transport)
    kind = "turntable" if client.profile == "acutrol3000" else "line"
    error = error_pattern(kind, client.profile)
    with simulator(kind, client.profile, dict(client.profile_overrides)) as (endpoint, transport):
        proxy = RecordingProxy(endpoint, transport)
        try:
            for method in client.methods:
                member = MemberRecord(method.name, "request-list", method.where)
                record.members.append(member)
                if method.not_sent:
                    member.not_called = method.not_sent
                    continue
                member.calls.append(len(record.calls))
                call = CallRecord(method.name, method.call, f"{client.source}: {method.where}")
                record.calls.append(call)
                _replay(client, method.requests, call, proxy, error)
        finally:
            proxy.close()
    classify(record)
    record.seconds = round(time.monotonic() - started, 2)
    return record


def _replay(client: DataClient, requests: tuple[Expect, ...], call: CallRecord, proxy: RecordingProxy,
            error: re.Pattern[str] | None) -> None:
    """Each request sent as the client sends it, its reply read as the client reads it, on a new connection
    per method (a fresh session, as each method of these clients could be the first)."""
    mark = proxy.mark()
    read_end = client.read_terminator.encode()
    problems = []
    with socket.create_connection(("127.0.0.1", proxy.port), timeout=5) as connection:
        for expect in requests:
            connection.sendall(expect.request.encode("latin-1") + client.write_terminator.encode())
            reply = _read_reply(connection, read_end, client.reply_wait_s)
            problem = expect.check(reply) or _unmodelled_setting(client.profile, expect)
            problems.append(problem)
    proxy.settle()
    call.exchanges = exchanges(proxy.since(mark), error, False)
    if len(call.exchanges) == len(requests):
        for index, (exchange, expect) in enumerate(zip(call.exchanges, requests)):
            if exchange.simulator == "refused" and not problems[index] and not expect.refusal:  # an error reply is
                # no documented answer, unless the maker documents that refusal for this request in this state
                problems[index] = f"refused: {exchange.detail}; documented: {expect.source}"
            exchange.documented = expect.source if expect.answer is None else f"{expect.answer!r}: {expect.source}"
            exchange.problem = problems[index]
    call.outcome = "returned" if not any(problems) else "raised"
    call.value = "; ".join(f"{e.request!r}: {p}" for e, p in zip(requests, problems) if p)


def _unmodelled_setting(profile: str, expect: Expect) -> str:
    """An SCPI setting the simulated F4T does not know goes unanswered, as every unknown header does: it is
    documented as unanswered, but nothing of it is carried out."""
    protocol = LINE_PROFILES.get(profile)
    if expect.answer is not None or protocol is None or protocol.dialect != "scpi":
        return ""
    if any(pattern.fullmatch(expect.request) for _, _, pattern in protocol.request_patterns()):  # type: ignore[attr-defined]
        return ""
    if f4t_serves(expect.request):  # held by the simulated F4T beyond its profile (sim/f4t_scpi_extras.py)
        return ""
    return "a documented setting the simulator does not know: unanswered as documented, but not carried out"


def _read_reply(connection: socket.socket, end: bytes, wait_s: float) -> bytes:
    """Whatever comes back within wait_s, up to and including the first line end."""
    received = b""
    deadline = time.monotonic() + wait_s
    while end not in received:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            break
        connection.settimeout(remaining)
        try:
            data = connection.recv(65536)
        except TimeoutError:
            break
        if not data:
            break
        received += data
    return received


# ---------------------------------------------------------------------- verdicts
@dataclass(frozen=True)
class Documented:
    """A refusal or a silence the maker documents for that request on a controller in the simulated state."""

    profile: str
    request: str  # a regular expression over the request text (its terminator cut)
    reply: str  # a regular expression the reply must match in full ('' : no reply)
    source: str  # where the maker says so


DOCUMENTED: tuple[Documented, ...] = (
    # the line profiles' refusals, as data (maker_requests.REFUSALS, each checked against the simulator)
    *(Documented(r.profile, r.request, re.escape(r.reply), f"{r.source} ({r.state}" + ("; the code inferred from "
      "the error table's meanings)" if r.inferred else ")")) for r in LINE_REFUSALS),
    Documented("watlow-f4", r"read holding (319|1925) x1", "exception 2",
               "ChamberConnectLibrary watlowf4.py process_controller (lines 952-966): loop 2's set point (319) and the "
               "cascade flag (1925) are probed, an exception meaning a single-loop F4 without cascade, as simulated"),
)


@dataclass(frozen=True)
class ClientLimit:
    """A client that cannot read what its controller documents (its own limitation, not the simulator's)."""

    client: str
    member: str
    error: str  # a regular expression over the client's exception
    why: str


CLIENT_LIMITS: tuple[ClientLimit, ...] = (
    *(ClientLimit(f"ChamberConnectLibrary {name}", r"^sample$", r"NoneType",
                  "sample()'s default lookup=None is indexed before it is checked (controllerinterface.py:1046-1047): "
                  "the library's own bug; every request it sent was answered") for name in ("WatlowF4", "WatlowF4T")),
    ClientLimit("PyMeasure Thermotron3800, PyVISA's terminations", r".*", r"VI_ERROR_TMO",
                "PyVISA's TCPIP SOCKET resource has no read termination unless one is given: the reply came (see "
                "the wire) and was read only up to the timeout; a Thermotron3800 on a socket needs read_termination"),
    ClientLimit("espec-pr3j", r"get_temperature_status|get_test_area_state|set_target_temperature|"
                r"set_constant_condition",
                r"MonitorError|SettingError",
                "its reply patterns have no minus sign (src/espec_pr3j/espec_pr3j.py: r'(?P<current>\\d+\\.\\d+)'): a "
                "chamber below 0 °C, or with a lower limit below 0 °C, cannot be read (test_public_clients.py)"),
    ClientLimit("py-lab-hal Pu3j", r"^read_actual_temp$|^read_set_point$", r"ValueError|IndexError",
                "py_lab_hal/instrument/temp_chamber/pu3j.py reads TEMP? split on ', ' (comma and blank), where the "
                "P300's reply as ChamberConnectLibrary's read_temp parses it (split on ',') has no blank; and it "
                "writes commands with send() without reading the OK:/NA: every command is answered with, so a "
                "later query may read an earlier reply (every request it sent was answered, see the wire)"),
)


def _request_text(exchange: Exchange) -> str:
    return exchange.text


def _reply_text(exchange: Exchange) -> str:
    return exchange.reply_text


def _shape(text: str) -> str:
    """A request's shape for the NOT_SIMULATED lists: numbers as `#`, blanks after commas dropped, any case; a
    SIMSERV request keeps its command number (the first field: the command itself)."""
    head, separator, rest = text.strip().partition("\u00b6")
    if separator and head.isdigit():
        return head + separator + _shape(rest)
    return re.sub(r"[-+]?\d+(\.\d+)?", "#", re.sub(r",\s+", ",", text.strip())).lower()


#: The requests already on record as not simulated (tests/protocols/maker_requests.py and
#: turntable_requests.py): profile → {shape: why}.
LISTED: dict[str, dict[str, str]] = {}
for _profile, _request, _client, _where, _why in CHAMBER_NOT_SIMULATED:
    LISTED.setdefault(_profile, {})[_shape(_request)] = f"{_why} (maker_requests.NOT_SIMULATED: {_client} {_where})"
for _profile, _prefix, _request, _client, _where, _answer, _why in UNDOCUMENTED_SPELLINGS:
    LISTED.setdefault(_profile, {})[_shape(_prefix + _request)] = f"{_why} (maker_requests.UNDOCUMENTED_SPELLINGS: " \
                                                                  f"{_client} {_where})"
for _request, _client, _where, _why in TURNTABLE_NOT_SIMULATED:
    LISTED.setdefault("acutrol3000", {})[_shape(_request)] = f"{_why} (turntable_requests.NOT_SIMULATED: {_client} " \
                                                             f"{_where})"


def listed(profile: str, exchange: Exchange) -> str | None:
    """Why the request is not simulated, where it is already listed so; None: not listed."""
    register = re.match(r"(?:read holding|write) (\d+)", exchange.text)
    if register is not None:
        entry = modbus_not_simulated(profile, int(register.group(1)))
        return f"{entry.why} (modbus_requests.NOT_SIMULATED: {entry.client} {entry.where})" if entry else None
    return LISTED.get(profile, {}).get(_shape(exchange.text))


_SCPI_SETTING = Documented("watlow-f4t-scpi", r"[^?]*", "", "F4T list (PaulNongL/WatlowF4TscpiLibrary "
                           "f4t_scpi_cmds/f4t_scpi_commands.ods): a W row, a setting, is unanswered (only queries "
                           "answer); this one the simulated F4T carries out")


def documented(profile: str, exchange: Exchange) -> Documented | None:
    for entry in DOCUMENTED:
        if entry.profile == profile and re.fullmatch(entry.request, _request_text(exchange)) \
                and re.fullmatch(entry.reply, _reply_text(exchange)):
            return entry
    if profile == _SCPI_SETTING.profile and exchange.simulator == "silence" and "?" not in exchange.text \
            and not _unmodelled_setting(profile, Expect(exchange.text, None, "")):
        return _SCPI_SETTING  # a setting the simulator knows, unanswered as every SCPI setting is
    return None


def _off(record: ClientSweep, call: CallRecord) -> list[Exchange]:
    """The exchanges of a call that are not as the maker documents."""
    if any(e.documented for e in call.exchanges):  # a request-list client's: checked against its documented answer
        return [e for e in call.exchanges if e.problem]
    return [e for e in call.exchanges if e.simulator != "answered" and documented(record.profile, e) is None]


def classify(record: ClientSweep) -> None:
    for call in record.calls:
        if call.outcome in ("", "not-called"):
            call.verdict, call.why = "not-exercised", call.why or "not called"
            continue
        off = _off(record, call)
        limit = next((lim for lim in CLIENT_LIMITS if lim.client == record.client and re.search(lim.member, call.member)
                      and re.search(lim.error, call.value)), None)
        on_record = [e for e in off if listed(record.profile, e)]
        off = [e for e in off if not listed(record.profile, e)]
        if off:
            call.verdict = "deviation"
            call.why = "; ".join(f"{_request_text(e)!r} {e.simulator}" + (f" ({e.detail})" if e.detail else "")
                                 + (f": {e.problem}" if e.problem else "") for e in off)
        elif on_record:
            call.verdict = "not-simulated"
            call.why = "; ".join(f"{e.text!r}: {listed(record.profile, e)}" for e in on_record)
        elif call.outcome == "raised" and any(documented(record.profile, e) for e in call.exchanges
                                              if e.simulator != "answered"):
            call.verdict = "as-documented"
            call.why = "; ".join(d.source for e in call.exchanges if (d := documented(record.profile, e)) is not None)
        elif call.outcome in ("raised",) and limit is not None:
            call.verdict, call.why = "client-limit", limit.why
        elif call.outcome == "raised" and not call.exchanges:
            call.verdict, call.why = "not-exercised", f"the client raised before sending anything: {call.value}"
        elif call.outcome == "raised":
            call.verdict, call.why = "deviation", f"every request answered, but the client could not read a reply: " \
                                                  f"{call.value}"
        elif not call.exchanges and call.outcome in ("returned", "constructed"):
            call.verdict, call.why = "sends-nothing", ""
        else:
            call.verdict = "as-documented"
            call.why = "; ".join(d.source for e in call.exchanges if (d := documented(record.profile, e)) is not None)
            if call.outcome == "deadline":
                call.why = (call.why + "; " if call.why else "") + "every request answered; the client still " \
                                                                   "polling at its deadline"


# ---------------------------------------------------------------------- counts and the survey
@dataclass
class Counts:
    client: str
    profile: str
    members: int  # the client's own public methods and properties (or request-list methods)
    inherited: int  # framework members, enumerated and not called
    exercised: int  # members called at least once
    not_exercised: int
    calls: int
    requests: int
    distinct_requests: int
    as_documented: int  # members every call of which was answered as documented (or a documented refusal)
    deviating: int  # members with a deviating call
    deviations: int  # distinct deviating requests (or unreadable replies)
    not_simulated: int  # members whose only departures are requests already listed as NOT_SIMULATED
    client_limits: int


def counts(record: ClientSweep) -> Counts:
    own = [m for m in record.members if m.kind in ("method", "property", "request-list")]
    verdicts = {m.name: [record.calls[i].verdict for i in m.calls] for m in own}
    exercised = [m for m in own if any(v not in ("not-exercised",) for v in verdicts[m.name])]
    deviating = [m for m in own if "deviation" in verdicts[m.name]]
    listed_ = [m for m in exercised if m not in deviating and "not-simulated" in verdicts[m.name]]
    documented_ = [m for m in exercised if m not in deviating and m not in listed_
                   and "client-limit" not in verdicts[m.name]]
    sent = [e for c in record.calls for e in c.exchanges if e.request != "b''"]
    return Counts(record.client, record.profile, len(own), sum(m.kind == "inherited" for m in record.members),
                  len(exercised), len(own) - len(exercised), sum(c.outcome not in ("", "not-called") for c in record.calls),
                  len(sent), len({e.request for e in sent}), len(documented_), len(deviating),
                  len(deviation_list(record)), len(listed_), sum(c.verdict == "client-limit" for c in record.calls))


def deviation_list(record: ClientSweep) -> dict[str, dict[str, object]]:
    """Distinct deviating requests: request text → what the simulator did, the members that sent it, the client's
    error and where in its source."""
    found: dict[str, dict[str, object]] = {}
    for call in record.calls:
        if call.verdict != "deviation":
            continue
        off = [e for e in _off(record, call) if not listed(record.profile, e)]
        if not off:  # a reply the client could not read: keyed by the last request it sent
            off = call.exchanges[-1:]
        for exchange in off:
            key = _request_text(exchange)
            entry = found.setdefault(key, {"simulator": exchange.simulator, "reply": exchange.reply,
                                           "detail": exchange.detail or exchange.problem, "members": [], "client": [],
                                           "frames": []})
            members: list[str] = entry["members"]  # type: ignore[assignment]
            if call.member not in members:
                members.append(call.member)
            if call.outcome == "raised" and call.value not in entry["client"]:  # type: ignore[operator]
                entry["client"].append(call.value)  # type: ignore[attr-defined]
            for frame in call.frames[-2:]:
                if frame not in entry["frames"]:  # type: ignore[operator]
                    entry["frames"].append(frame)  # type: ignore[attr-defined]
    return found


def sweep_all(workers: int = 6, names: set[str] | None = None) -> list[ClientSweep]:
    """Every installable client and every request-list client, a few at a time (each has its own simulator)."""
    jobs: list[Callable[[], ClientSweep]] = []
    for spec in CLIENTS:
        if names is None or spec.name in names:
            jobs.append(lambda spec=spec: sweep_client(spec))  # type: ignore[misc]
    for client in DATA_CLIENTS:
        if names is None or client.name in names:
            jobs.append(lambda client=client: sweep_data_client(client))  # type: ignore[misc]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda job: job(), jobs))


def markdown(records: list[ClientSweep]) -> str:
    lines = ["| client | profile | members | inherited (not called) | exercised | not exercised | calls | requests "
             "(distinct) | members answered as documented | members deviating | deviating requests | members only "
             "NOT_SIMULATED | client limits |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for record in records:
        c = counts(record)
        lines.append(f"| {c.client} | {c.profile} | {c.members} | {c.inherited} | {c.exercised} | {c.not_exercised} | "
                     f"{c.calls} | {c.requests} ({c.distinct_requests}) | {c.as_documented} | {c.deviating} | "
                     f"{c.deviations} | {c.not_simulated} | {c.client_limits} |")
    for record in records:
        lines += ["", f"## {record.client} ({record.profile})", "", f"Source: {record.source}. Transport: "
                  f"{record.transport}. {record.seconds} s."]
        if record.problem:
            lines.append(f"\n**Not run**: {record.problem}")
        lines += ["", "| member | verdict | calls | requests → what the simulator did | client |", "|---|---|---|---|---|"]
        for member in record.members:
            if member.kind in ("inherited", "attribute", "class"):
                continue
            calls = [record.calls[i] for i in member.calls]
            if not calls:
                lines.append(f"| `{member.name}` | not exercised | — | — | {member.not_called or ''} |")
                continue
            verdicts = sorted({c.verdict for c in calls})
            wire = "<br>".join(f"`{_request_text(e)!s}` → " + (f"`{_reply_text(e)}`" if e.simulator == 'answered'
                                                                else f"**{e.simulator}** {e.detail}")
                               for c in calls for e in c.exchanges[:6])
            client = "<br>".join(f"{c.outcome}: {c.value[:120]}" for c in calls if c.outcome != "returned")
            lines.append(f"| `{member.name}` | {', '.join(verdicts)} | {len(calls)} | {wire} | {client} |")
        inherited = [m.name for m in record.members if m.kind == "inherited"]
        if inherited:
            lines.append(f"\nInherited framework members, enumerated, not called: {', '.join(inherited)}.")
        deviations = deviation_list(record)
        if deviations:
            lines += ["", "Deviating requests:", ""]
            for request, entry in deviations.items():
                lines.append(f"- `{request}` — simulator: {entry['simulator']} {entry['detail']} (reply "
                             f"{entry['reply']}); sent by {', '.join(entry['members'])}"  # type: ignore[arg-type]
                             + (f"; client: {'; '.join(entry['client'])}" if entry["client"] else "")  # type: ignore[arg-type]
                             + (f"; source: {' | '.join(entry['frames'])}" if entry["frames"] else ""))  # type: ignore[arg-type]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", type=Path, help="write the survey's tables here")
    parser.add_argument("--json", type=Path, help="write every record here")
    parser.add_argument("--only", action="append", help="a client's name (repeat)")
    args = parser.parse_args(argv)
    records = sweep_all(names=set(args.only) if args.only else None)
    if args.json:
        args.json.write_text(json.dumps([asdict(r) for r in records], indent=1))
    text = markdown(records)
    if args.markdown:
        args.markdown.write_text(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
