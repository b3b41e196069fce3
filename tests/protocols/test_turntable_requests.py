"""The public ACL clients' requests and the manual's examples (tests/protocols/turntable_requests.py),
replayed in order against the simulated ACUTROL3000 on a pty; every reply goes through the driver's own
reply parsing, and its values are the simulated table's."""

from __future__ import annotations

import re

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.turntable_serial import read_reply
from accelcal_rig.protocols.turntable_line import ACUTROL3000
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG
from tests.protocols.turntable_requests import CONVERSATIONS, NOT_SIMULATED, ON_GPIB, Conversation, Row
from tests.sim.line_client import LineClient, pty_client

_COMMANDS = dict(ACUTROL3000.commands())


class Table:
    """A fresh simulated controller and a plain client of it."""

    def __init__(self, client: LineClient, server: SimulatedTurntableServer, lab: VirtualLab) -> None:
        self.client, self.server, self.lab = client, server, lab

    def ask(self, request: str) -> str:
        self.client.send(request.encode() + b"\n")
        return self.client.reply(b"\n").removesuffix(b"\n").decode()

    def angle(self) -> float:
        """Axis 1's angle as the driver reads it (also: whatever was sent before went unanswered)."""
        request = ACUTROL3000.request(ACUTROL3000.position, axis=1)
        return float(read_reply(ACUTROL3000, ACUTROL3000.position, request, self.ask(request), "pty")["angle"])


def replay(row: Row, table: Table) -> None:
    table.lab.clock.sleep(row.wait_s)
    if row.silent:
        table.client.send(row.request.encode() + b"\n")
    else:
        reply = table.ask(row.request)
        if row.refused:
            with pytest.raises(InstrumentError, match="refused"):
                read_reply(ACUTROL3000, _COMMANDS["position"], row.request, reply, "pty")
        else:
            assert not re.search(ACUTROL3000.error_pattern, reply), reply
        if row.reply is not None:
            assert re.fullmatch(row.reply, reply), reply
        if row.operations:
            answers = reply.split(";")
            assert len(answers) == len(row.operations), reply
            now = table.lab.clock.now()
            for operation, answer in zip(row.operations, answers, strict=True):
                values = read_reply(ACUTROL3000, _COMMANDS[operation], row.request, answer, "pty")
                if "angle" in values:
                    assert float(values["angle"]) in [pytest.approx(a, abs=1e-4)
                                                      for a in table.lab.motion.position_deg(now)]
                if "rate" in values:
                    assert abs(float(values["rate"])) < 1.0
                if "identity" in values:
                    assert values["identity"] == "accelcal-rig simulated turntable"
                if "fault" in values:
                    assert values["fault"] not in ACUTROL3000.fault_values
    table.angle()  # nothing else came (the next reply is this read's), and the request has been taken
    if row.axis1_deg is not None:
        table.lab.clock.sleep(120.0)
        assert table.angle() == pytest.approx(row.axis1_deg, abs=0.01)


@pytest.mark.parametrize("conversation", CONVERSATIONS, ids=[c.client for c in CONVERSATIONS])
def test_each_public_clients_requests_are_understood_or_refused_as_the_manual_says(
        conversation: Conversation) -> None:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, ACUTROL3000).start()
    try:
        with pty_client(server.endpoint) as client:
            table = Table(client, server, lab)
            for row in conversation.rows:
                try:
                    replay(row, table)
                except AssertionError as exc:
                    raise AssertionError(f"{conversation.client} {row.where}: {row.request!r}: {exc}") from exc
    finally:
        server.stop()


@pytest.mark.parametrize(("request_text", "client", "where", "why"), NOT_SIMULATED)
def test_what_the_simulator_does_not_model_is_answered_as_unknown(request_text: str, client: str, where: str,
                                                                    why: str) -> None:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, ACUTROL3000).start()
    try:
        with pty_client(server.endpoint) as line:
            table = Table(line, server, lab)
            assert re.match(ACUTROL3000.error_pattern, table.ask(request_text))  # unknown, or (ALL) no axis
            assert re.search(r"§\d|Table \d", why), "each reason cites the manual"
    finally:
        server.stop()


def test_the_gpib_difference_is_on_record() -> None:
    """A real controller on GPIB answers a command it does not carry out with silence (TM-8004-C Table 1): the
    simulator's ERR line is a named difference, not an oversight."""
    assert "Table 1" in ON_GPIB and "ERR" in ON_GPIB


def test_a_tripped_interlock_sets_the_status_byte() -> None:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedTurntableServer(lab, ACUTROL3000).start()
    try:
        with pty_client(server.endpoint) as line:
            table = Table(line, server, lab)
            server.faults[1] = "Fault"
            assert table.ask("*stb?") == "65"  # IEAv's interlock error
            assert table.ask(":interlock? 2;:interlock? 1") == "Fault;0"
    finally:
        server.stop()
