"""The makers' and other public clients' requests (tests/protocols/maker_requests.py), replayed in order
against each profile's simulated controller over loopback TCP; every reply goes through the driver's own
reply parsing and its values must be the simulated chamber's state."""

from __future__ import annotations

import re
from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.instruments.chamber_line import read_reply
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, ChamberLineProtocol, line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG
from tests.protocols.maker_requests import (
    CONVERSATIONS,
    NOT_SIMULATED,
    REFUSALS,
    UNDOCUMENTED_SPELLINGS,
    Conversation,
    Refusal,
    Row,
    S,
)
from tests.sim.line_client import LineClient, tcp_client


@contextmanager
def controller(protocol: ChamberLineProtocol) -> Iterator[tuple[SimulatedLineChamberServer, VirtualLab, LineClient]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedLineChamberServer(lab, protocol, "tcp").start()
    try:
        with tcp_client(server.endpoint) as client:
            yield server, lab, client
    finally:
        server.stop()


class Wire:
    """A client of one profile's controller: text out with the profile's terminator, reply lines in."""

    def __init__(self, protocol: ChamberLineProtocol, client: LineClient) -> None:
        self.protocol, self._client = protocol, client
        self._end = protocol.read_terminator.encode(protocol.encoding)

    def send(self, request: str, ending: str | None = None) -> None:
        end = self.protocol.write_terminator if ending is None else ending
        self._client.send((request + end).encode(self.protocol.encoding))

    def reply(self) -> str:
        return self._client.reply(self._end).removesuffix(self._end).decode(self.protocol.encoding)

    def assert_nothing_came(self) -> None:
        """Whatever was sent went unanswered: the reply to a set point read is the next line."""
        request = self.protocol.request("read_setpoint")
        self.send(request)
        read_reply(self.protocol, "read_setpoint", request, self.reply(), "simulated")


def check_values(values: dict[str, str], protocol: ChamberLineProtocol, server: SimulatedLineChamberServer,
                 lab: VirtualLab) -> None:
    """What the driver read is the simulated chamber's state (to the answer's rounding and the air's noise)."""
    now = lab.clock.now()
    setpoint = server.last_setpoint_c if server.last_setpoint_c is not None else lab.thermal.setpoint_c
    low, high = lab.controller_limits_c
    expected = {"sp": (setpoint, 0.05), "low": (low, 0.05), "high": (high, 0.05),
                "pv": (lab.thermal.air_c(now), 6 * lab.chamber_noise_c + 0.05),
                "humidity": (lab.chamber_humidity_pct(), 0.5)}
    for name, (value, tolerance) in expected.items():
        if name in values:
            assert float(values[name]) == pytest.approx(value, abs=tolerance), name
    if "alarm" in values:
        assert protocol.alarm_means_active(values["alarm"]) == (server.alarms > 0)
    if "identity" in values:
        assert server.identity in values["identity"]
    if "units" in values:
        assert values["units"] == protocol.units_celsius


def replay(row: Row, wire: Wire, server: SimulatedLineChamberServer, lab: VirtualLab) -> None:
    protocol = wire.protocol
    wire.send(row.request, row.ending)
    command = protocol.command(row.operation) if row.operation is not None else None
    if row.silent:
        assert command is None or command.reply is None, "a silent row of an answered operation"
        wire.assert_nothing_came()
    else:
        reply = wire.reply()
        if row.refused is not None:
            assert reply == row.refused
        if row.reply is not None:
            assert re.fullmatch(row.reply, reply), reply
        if row.operation is not None:
            request = row.request.removeprefix(protocol.request_prefix)
            check_values(read_reply(protocol, row.operation, request, reply, "simulated"), protocol, server, lab)
        elif row.refused is None:
            assert not re.search(protocol.error_pattern, reply), reply
    if row.setpoint_c is not None:
        assert server.last_setpoint_c == pytest.approx(row.setpoint_c)
    if row.powered is not None:
        assert lab.thermal.powered is row.powered
    if row.purge is not None:
        assert lab.moisture.purge_on is row.purge
    if row.limits_c is not None:
        assert lab.controller_limits_c == pytest.approx(row.limits_c)


@pytest.mark.parametrize("conversation", CONVERSATIONS,
                         ids=[f"{c.profile}-{c.client}-{i}" for i, c in enumerate(CONVERSATIONS)])
def test_each_public_clients_requests_are_understood_or_refused_as_the_protocol_says(
        conversation: Conversation) -> None:
    protocol = line_protocol(conversation.profile, conversation.overrides)
    with controller(protocol) as (server, lab, client):
        wire = Wire(protocol, client)
        for row in conversation.rows:
            try:
                replay(row, wire, server, lab)
            except AssertionError as exc:
                raise AssertionError(f"{conversation.client} {row.where}: {row.request!r}: {exc}") from exc


def test_every_profile_has_public_clients_on_record() -> None:
    assert {c.profile for c in CONVERSATIONS} == set(LINE_PROFILES)


@pytest.mark.parametrize(("profile", "request_text", "client", "where", "why"), NOT_SIMULATED)
def test_what_the_simulator_does_not_model_is_answered_as_the_controller_answers_what_it_does_not_support(
        profile: str, request_text: str, client: str, where: str, why: str) -> None:
    """The gap list is true: each is met with the profile's own 'not supported' (ESPEC `NA:INVALID REQ`,
    SIMSERV `-8`), or where it has none as an unknown request (silence on the Thermotron and the F4T)."""
    protocol = LINE_PROFILES[profile]
    answer = protocol.unsupported_answer or protocol.unknown_command_answer
    with controller(protocol) as (_, _, client_line):
        wire = Wire(protocol, client_line)
        wire.send(request_text)
        if answer is not None:
            assert wire.reply() == answer
        else:
            wire.assert_nothing_came()


@pytest.mark.parametrize(("profile", "prefix", "request_text", "client", "where", "answer", "why"),
                         UNDOCUMENTED_SPELLINGS)
def test_a_spelling_the_maker_does_not_document_is_answered_as_recorded(
        profile: str, prefix: str, request_text: str, client: str, where: str, answer: str, why: str) -> None:
    protocol = line_protocol(profile, {"request_prefix": prefix})
    with controller(protocol) as (_, _, client_line):
        wire = Wire(protocol, client_line)
        wire.send(prefix + request_text)  # the address in front, as the client writes it
        assert wire.reply() == answer


@pytest.mark.parametrize("refusal", REFUSALS, ids=[f"{r.profile}-{r.reply}-{r.state}" for r in REFUSALS])
def test_each_documented_refusal_is_what_the_simulated_controller_answers_in_its_state(refusal: Refusal) -> None:
    """The refusals the sweep takes as documented (client_sweep.DOCUMENTED) are true of the simulator, and each
    example is one of the requests the entry covers."""
    protocol = LINE_PROFILES[refusal.profile]
    assert refusal.reply in {f"NA:{code}" for code in protocol.errors} | {"NA:PRGM WRITE ERR-2", "NA:PRGM WRITE ERR-3"}
    with controller(protocol) as (_, _, client_line):
        wire = Wire(protocol, client_line)
        for example in refusal.examples:
            assert re.fullmatch(refusal.request, example), example
            wire.send(example)
            assert wire.reply() == refusal.reply, example


@pytest.mark.parametrize(("alarms", "warnings", "status", "active"), [
    (0, 0, 3, False), (0, 1, 7, False), (1, 0, 11, True), (2, 3, 15, True)])
def test_simserv_status_follows_the_chambers_alarms_and_warnings(alarms: int, warnings: int, status: int,
                                                                 active: bool) -> None:
    protocol = LINE_PROFILES["simserv"]
    with controller(protocol) as (server, _, client):
        server.alarms, server.warnings = alarms, warnings
        wire = Wire(protocol, client)
        for request in (f"10012{S}1", f"10012{S}1{S}1"):  # IzaakWN's and basil's spellings
            wire.send(request)
            reply = wire.reply()
            assert reply == f"1{S}{status}"
            assert protocol.alarm_means_active(read_reply(protocol, "alarm", request, reply, "simulated")["alarm"]) \
                is active


def test_an_alarm_bit_is_a_rig_config_setting() -> None:
    """A rig that treats SIMSERV warnings as alarms too sets alarm_bits to 12."""
    strict = line_protocol("simserv", {"alarm_bits": 12})
    assert strict.alarm_means_active("7") and not LINE_PROFILES["simserv"].alarm_means_active("7")
    assert not strict.alarm_means_active("3")
