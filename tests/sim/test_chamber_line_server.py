"""The simulated line chamber controllers, byte for byte over loopback TCP and a pseudo-terminal as any client
sees them: a set point that is no number (`nan`, `inf`, `1e400`, Python-only spellings) is refused with the
answer the profile gives a request it cannot read (ESPEC `NA:CMD ERR`, SIMSERV `-5`; the Thermotron and the
SCPI F4T stay silent), and the set point before it stays; a line too long to be a request is answered the
same way, held only up to the bound, and the next request is answered."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.instruments.chamber_line import LineChamber
from accelcal_rig.protocols.chamber_lines import line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.line_answers import MAX_LINE_BYTES
from tests.conftest import SIM_RIG
from tests.sim.line_client import LineClient, pty_client, tcp_client

S = b"\xb6"  # SIMSERV's field separator

#: Each profile: writing -40 and its answer, a set point request with `%s` for the number, the answer to a
#: number it cannot read (None: silence), and reading the set point back with its answer at -40.
PROFILES = {
    "espec-p300": (b"TEMP, S-40.0\r\n", b"OK:TEMP, S-40.0\r\n", b"TEMP, S%s\r\n", b"NA:CMD ERR\r\n",
                   b"TEMP?\r\n", b",-40.0,180.0,-70.0\r\n"),
    "simserv": (b"11001" + S + b"1" + S + b"1" + S + b"-40.0\r", b"1\r\n", b"11001" + S + b"1" + S + b"1" + S + b"%s\r",
                b"-5\r\n", b"11002" + S + b"1" + S + b"1\r", b"1" + S + b"-40.0\r\n"),
    "thermotron-8800": (b"SETP1,-40.0\r", b"0\r\n", b"SETP1,%s\r", None, b"SETP1?\r", b"-40.00\r\n"),
    "watlow-f4t-scpi": (b":SOURCE:CLOOP1:SPOINT -40.00\n", None, b":SOURCE:CLOOP1:SPOINT %s\n", None,
                        b":SOURCE:CLOOP1:SPOINT?\n", b"-40.00\n"),
}
NOT_NUMBERS = [b"nan", b"NaN", b"inf", b"-inf", b"Infinity", b"1e400", b"-1e400", b"1_0", b"0x10", b"4O"]


@contextmanager
def served(profile: str, transport: str) -> Iterator[tuple[SimulatedLineChamberServer, LineClient]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedLineChamberServer(lab, line_protocol(profile), transport).start()
    try:
        with (tcp_client if transport == "tcp" else pty_client)(server.endpoint) as client:
            yield server, client
    finally:
        server.stop()


def reply_terminator(profile: str) -> bytes:
    return line_protocol(profile).read_terminator.encode()


@pytest.mark.parametrize("transport", ["tcp", "pty"])
@pytest.mark.parametrize("profile", sorted(PROFILES))
def test_a_set_point_that_is_no_number_is_refused_as_the_profile_refuses_and_the_old_one_stays(
        profile: str, transport: str) -> None:
    write, written, bad, refused, read_back, read = PROFILES[profile]
    end = reply_terminator(profile)
    with served(profile, transport) as (server, client):
        client.send(write)
        if written is not None:
            assert client.reply(end) == written
        for text in NOT_NUMBERS:
            client.send(bad % text)
            if refused is not None:
                assert client.reply(end) == refused, text
            client.send(read_back)  # a silent profile's next reply is this one's
            assert client.reply(end).endswith(read), text
        assert server.last_setpoint_c == -40.0


@pytest.mark.parametrize("profile", sorted(PROFILES))
def test_the_driver_reads_the_controller_after_a_refused_set_point(profile: str) -> None:
    """`TEMP, Snan` used to be taken, and every later `rig check` refused the controller's set point."""
    write, written, bad, refused, read_back, read = PROFILES[profile]
    with served(profile, "tcp") as (server, client):
        client.send(bad % b"nan")
        client.send(read_back)
        client.reply(reply_terminator(profile))
        chamber = LineChamber.open(server.endpoint, line_protocol(profile), timeout_s=2.0)
        try:
            assert "PV 23" in chamber.identify()
        finally:
            chamber.close()


@pytest.mark.parametrize("transport", ["tcp", "pty"])
@pytest.mark.parametrize("profile", sorted(PROFILES))
def test_a_multi_megabyte_line_is_answered_as_unknown_and_held_only_to_the_bound(profile: str, transport: str) -> None:
    write, written, bad, refused, read_back, read = PROFILES[profile]
    end = reply_terminator(profile)
    request_end = line_protocol(profile).write_terminator.encode()
    with served(profile, transport) as (server, client):
        for _ in range(64):  # 4 MiB without a terminator
            client.send(b"9" * 65536)
        client.send(request_end)
        if refused is not None:
            assert client.reply(end) == refused
        client.send(write)
        if written is not None:
            assert client.reply(end) == written
        client.send(read_back)
        assert client.reply(end).endswith(read)  # every byte before it has been read and answered by now
        assert 0 < server.peak_buffered_bytes <= MAX_LINE_BYTES + len(request_end) - 1
        assert server.buffered_bytes == 0


@pytest.mark.parametrize("transport", ["tcp", "pty"])
def test_the_thermotron_answers_a_request_ended_by_cr_lf_or_cr_lf_alone_and_never_joins_two(transport: str) -> None:
    """Its clients end requests with CR (the profile), CR LF (PyVISA's default) or LF: each is answered on its
    own, and an LF-ended request does not swallow the next (issue 43: `IDEN?\\nPVAR1?\\n` was no request)."""
    with served("thermotron-8800", transport) as (server, client):
        client.send(b"SETP1,-40.0\n")
        assert client.reply(b"\r\n") == b"0\r\n"
        for ending in (b"\n", b"\r", b"\r\n"):
            client.send(b"SETP1?" + ending)
            assert client.reply(b"\r\n") == b"-40.00\r\n", ending
        client.send(b"IDEN?\nSETP1?\r\n")
        assert client.reply(b"\r\n") == server.identity.encode() + b"\r\n"
        assert client.reply(b"\r\n") == b"-40.00\r\n"
        assert server.buffered_bytes == 0
