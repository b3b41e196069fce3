"""One bridge protocol: the conformance table (tests/protocols/bridge_conformance.py, written from
docs/instruments.md) sent line by line to the reference firmware's host build and to the Python simulator, for
the ADXL355 and the ICM-42688-P, by a plain client on each pseudo-terminal. Both must give every reply the table
promises, the same line where the table gives one, and nothing but printable ASCII with no host language's error
text in it. Also the rules a table of single lines cannot hold, for both: a line left unfinished for a second is
dropped; a client that closes the port ends its conversation, so the rest of its reply is not read by the next
client, nor does its half-sent request spoil the next client's first."""

from __future__ import annotations

import os
import re
import select
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.core.descriptors import read_within
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.icm42688_bridge_server import SimulatedIcm42688Bridge
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import REPO, SIM_RIG
from tests.firmware.host_firmware import running, wait_until
from tests.protocols.bridge_conformance import GREETING, NO_REPLY, Exchange, exchanges

PARTS = ("adxl355", "icm42688p")
#: What a reply may never contain: the host language's own words for a failure.
HOST_ERROR_TEXT = re.compile(r"Traceback|Error|Exception|invalid literal|int\(\)|errno|NULL|object at 0x|\\x", re.I)
#: Longest a reply may take (generous: a loaded machine); a missing reply is recorded, and the table goes on.
REPLY_DEADLINE_S = 5.0


@dataclass
class Served:
    """A bridge on a pseudo-terminal."""

    path: str
    #: Lets time pass for the part behind it (the simulator's virtual clock; the firmware's own clock runs by itself).
    let_time_pass: Callable[[float], None]
    #: How many times a client has come or gone, as the bridge saw it: what a test waits on (never on time).
    session: Callable[[], int]


@contextmanager
def simulator(part: str) -> Iterator[Served]:
    """The Python simulator of `part` behind its bridge."""
    rig = SIM_RIG if part == "adxl355" else REPO / "configs" / "sim-imu.yaml"
    clock = VirtualClock()
    lab = VirtualLab(load_rig(rig).model, clock, 0)
    server = (SimulatedBridgeServer(lab, 0) if part == "adxl355" else SimulatedIcm42688Bridge(lab, 0)).start()
    try:
        yield Served(server.path, clock.sleep, lambda: server.session)
    finally:
        server.stop()


@contextmanager
def firmware(binary: Path, part: str, clock: str = "board") -> Iterator[Served]:
    """The reference firmware's host build in front of its C model of `part`."""
    with running(binary, "--part", part, clock=clock) as served:
        printed = [b""]

        def session() -> int:
            """The latest `session N` line the host build printed (it prints one as it sees a client come or go);
            read with os.read, past the line of its path the harness read."""
            assert served.process.stdout is not None
            fd = served.process.stdout.fileno()
            while select.select([fd], [], [], 0)[0]:
                chunk = os.read(fd, 4096)
                if not chunk:
                    break
                printed[0] += chunk
            numbers = re.findall(rb"^session (\d+)$", printed[0], re.MULTILINE)
            return int(numbers[-1]) if numbers else 0

        yield Served(served.path, lambda seconds: None, session)


class RawClient:
    """Bytes out, reply lines in: no serial library between the table and the bridge."""

    def __init__(self, fd: int) -> None:
        self._fd, self._held = fd, b""

    def send(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            view = view[os.write(self._fd, view):]

    def line(self, deadline_s: float = REPLY_DEADLINE_S) -> bytes | None:
        """The next reply line without its LF; None if none is complete by the deadline."""
        end = time.monotonic() + deadline_s
        while b"\n" not in self._held:
            got = read_within(self._fd, end)
            if not got:
                return None
            self._held += got
        line, _, self._held = self._held.partition(b"\n")
        return line

    def some(self, most: int = 256) -> bytes:
        """The first `most` bytes that arrive (waiting for them), besides what is held: the start of a long reply,
        never all of it. (One unbounded read can take a whole 36 kB reply: a tty read goes on while its writer
        keeps up.)"""
        if not self._held and select.select([self._fd], [], [], REPLY_DEADLINE_S)[0]:
            self._held = os.read(self._fd, most)
        some, self._held = self._held, b""
        return some

    def pending(self, wait_s: float) -> bytes:
        """Whatever arrives within `wait_s` (and what is held), without waiting for a line."""
        end = time.monotonic() + wait_s
        while (got := read_within(self._fd, end)) is not None and got:
            self._held += got
        pending, self._held = self._held, b""
        return pending


@contextmanager
def raw_client(path: str) -> Iterator[RawClient]:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        yield RawClient(fd)
    finally:
        os.close(fd)


def answers(path: str, table: list[Exchange], greeting: re.Pattern[str]) -> tuple[list[bytes | None], bytes]:
    """Each row's reply as it came (for a row that expects none: None if the next line is the reply to a `?` sent
    after it, so the row answered nothing; else that line), and what came beyond one line per request."""
    replies: list[bytes | None] = []
    with raw_client(path) as client:
        for row in table:
            client.send(row.send + b"\n")
            if row.reply is NO_REPLY:
                client.send(b"?\n")
            reply = client.line()
            if row.reply is NO_REPLY and reply is not None and greeting.fullmatch(reply.decode("latin-1")):
                reply = None
            replies.append(reply if reply is not None or row.reply is NO_REPLY else b"<no reply>")
        return replies, client.pending(0.2)


def problems_with(row: Exchange, reply: bytes | None, who: str) -> list[str]:
    """Why `reply` breaks the table's row (none: it keeps it)."""
    shown = f"{who}: {row.send[:40]!r} ({row.why}) answered {reply if reply is None else reply[:80]!r}"
    if reply is None:
        return [] if row.reply is NO_REPLY else [f"{shown}, expected {row.reply!r}"]
    problems = []
    if not all(0x20 <= byte <= 0x7E for byte in reply):
        problems.append(f"{shown}: not printable ASCII")
    text = reply.decode("latin-1")
    if HOST_ERROR_TEXT.search(text):
        problems.append(f"{shown}: a host language's error text")
    expected = row.reply
    if expected is NO_REPLY:
        problems.append(f"{shown}, expected no reply")
    elif text != expected if isinstance(expected, str) else not expected.fullmatch(text):
        problems.append(f"{shown}, expected {expected if isinstance(expected, str) else expected.pattern!r}")
    return problems


@pytest.mark.parametrize("part", PARTS)
def test_the_firmware_and_the_simulator_answer_the_table_alike(bridge_host: Path, part: str) -> None:
    """Every row, in order, from a bridge just started: each reply is the table's (the same line from both where
    the table gives the line; where the part's data decide, e.g. a temperature, both match the table's pattern)."""
    table = exchanges(part)
    with simulator(part) as served:
        simulated, simulated_beyond = answers(served.path, table, GREETING[part])
    with firmware(bridge_host, part) as served:
        reference, reference_beyond = answers(served.path, table, GREETING[part])
    problems = [problem for row, sim, ref in zip(table, simulated, reference, strict=True)
                for problem in problems_with(row, sim, "simulator") + problems_with(row, ref, "firmware")]
    problems += [f"{who}: more lines than requests: {beyond[:200]!r}"
                 for who, beyond in (("simulator", simulated_beyond), ("firmware", reference_beyond)) if beyond]
    assert not problems, f"{len(problems)} replies off the table:\n" + "\n".join(problems)


@pytest.mark.parametrize("implementation", ["simulator", "firmware"])
def test_a_line_left_unfinished_for_a_second_is_dropped(bridge_host: Path, implementation: str) -> None:
    """Half a request (a client that went away, noise from plugging in) is dropped once it is a second old, so the
    next request is read whole. (On the monotonic clock: the second is the time under test.)"""
    bridge = simulator("adxl355") if implementation == "simulator" else firmware(bridge_host, "adxl355", "monotonic")
    with bridge as served, raw_client(served.path) as client:
        client.send(b"R 0")
        time.sleep(1.1)  # the partial line's age under test
        client.send(b"?\n")
        reply = client.line()
        assert reply is not None and GREETING["adxl355"].fullmatch(reply.decode("latin-1")), reply
        client.send(b"R 0")
        client.send(b"0 1\n")  # a line sent in pieces within the second is one line
        assert client.line() == b"=AD"


#: A capture whose `G 0` reply (36 kB of hex) is far more than a pseudo-terminal holds (about 12 kB), at 1 kHz: the
#: FIFO lasts 32 ms, so a loaded machine seldom makes the firmware's capture overflow (it is taken again if it does).
BIG_CAPTURE_SAMPLES = 2000


def capture_a_big_block(client: RawClient, served: Served) -> None:
    """Bring the ADXL355 up at 1 kHz and capture BIG_CAPTURE_SAMPLES; returns once the capture is complete."""
    for request in (b"W 28 02", b"W 2D 00"):
        client.send(request + b"\n")
        assert client.line() == b"="
    for _ in range(3):
        client.send(b"C %d\n" % BIG_CAPTURE_SAMPLES)
        assert (started := client.line()) is not None and started.startswith(b"="), started
        served.let_time_pass(BIG_CAPTURE_SAMPLES / 1000 + 0.1)
        give_up = time.monotonic() + 20.0
        while (state := ask(client, b"G %d" % BIG_CAPTURE_SAMPLES)) == b"=":
            assert time.monotonic() < give_up, "the capture is not complete within 20 s"
            time.sleep(0.05)
        if state.startswith(b"=T"):
            return
        assert state.startswith(b"!overflow"), state
    raise AssertionError("the capture overflowed three times")


def ask(client: RawClient, request: bytes) -> bytes:
    client.send(request + b"\n")
    reply = client.line()
    assert reply is not None, f"no reply to {request!r}"
    return reply


@pytest.mark.parametrize("implementation", ["simulator", "firmware"])
def test_a_reply_whose_client_went_away_is_not_read_by_the_next_client(bridge_host: Path,
                                                                      implementation: str) -> None:
    """A client asks for a whole capture, reads the start of its reply and closes the port: the bridge sends
    nothing more of that reply, and what the port still held of it is dropped, so the next client to open the
    port reads only the replies to its own requests (opened once the bridge has seen the first one go)."""
    bridge = simulator("adxl355") if implementation == "simulator" else firmware(bridge_host, "adxl355")
    with bridge as served:
        with raw_client(served.path) as first:
            capture_a_big_block(first, served)
            first.send(b"G 0\n")
            taken = first.some()
            assert taken.startswith(b"=") and b"\n" not in taken  # the reply is under way, far from whole
            during = served.session()
        wait_until(lambda: served.session() > during, "the bridge seeing its client go")
        with raw_client(served.path) as second:
            assert second.pending(0.3) == b"", "the next client reads the rest of a reply it never asked for"
            assert ask(second, b"R 00 4") == b"=AD1DED01"
            tail = ask(second, b"G %d" % (BIG_CAPTURE_SAMPLES - 6))  # the capture is still there to fetch
            assert re.fullmatch(rb"=([0-9A-F]{18}){6}T[0-9A-F]{4}", tail), tail


@pytest.mark.parametrize("implementation", ["simulator", "firmware"])
def test_the_start_of_a_request_whose_client_went_away_is_dropped(bridge_host: Path, implementation: str) -> None:
    """Half a request from a client that closed the port does not spoil the next client's first request, well
    within the second after which any unfinished line is dropped."""
    bridge = simulator("adxl355") if implementation == "simulator" else firmware(bridge_host, "adxl355", "monotonic")
    with bridge as served:
        with raw_client(served.path) as first:
            first.send(b"R 0")
        time.sleep(0.2)  # far less than a second: the client's going is what drops its line
        with raw_client(served.path) as second:
            second.send(b"?\n")
            reply = second.line()
            assert reply is not None and GREETING["adxl355"].fullmatch(reply.decode("latin-1")), reply
