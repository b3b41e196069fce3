"""The simulated Watlow F4T beyond its profile: the F4T list's headers it holds are read in every spelling SCPI
allows, as the profile's own are; what it does not hold (another output, a setting that is no number, the
cascade headers) changes nothing and is met with silence, the F4T having no error reply."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.protocols.chamber_lines import line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.f4t_scpi_extras import serves
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG
from tests.sim.line_client import LineClient, tcp_client


@contextmanager
def f4t() -> Iterator[LineClient]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedLineChamberServer(lab, line_protocol("watlow-f4t-scpi"), "tcp").start()
    try:
        with tcp_client(server.endpoint) as client:
            yield client
    finally:
        server.stop()


def ask(client: LineClient, request: str) -> str:
    client.send(request.encode() + b"\n")
    return client.reply(b"\n").removesuffix(b"\n").decode()


def test_held_settings_are_read_back_in_any_spelling_and_what_is_not_held_changes_nothing() -> None:
    with f4t() as client:
        for setting in (":sour:clo2:spo 40", "SOURCE:CLOOP2:RRATE 3.5", ":OUTP7:STAT on", ":OUTPUT8:STATE ON",
                        ":SOURCE:CLOOP2:SPOINT nan", ":SOURCE:CLOOP2:RRATE fast", ":SOURCE:CASCADE1:SPOINT 20"):
            client.send(setting.encode() + b"\n")  # unanswered, each
        assert ask(client, "SOUR:CLO2:SPO?") == "40.00"
        assert ask(client, ":source:cloop2:rrate?") == "3.50"
        assert ask(client, ":OUTPut7:STATe?") == "ON"
        assert ask(client, ":SOURCE:CLOOP1:SPOINT?") == "23.00"  # nothing above went unread or was joined


@pytest.mark.parametrize(("request_text", "served"), [
    (":SOURCE:CLOOP1:RACTION OFF", True), (":SOURCE:CLOOP1:RACTION SETPOINT", False), (":OUTPUT7:STATE OFF", True),
    (":OUTPUT8:STATE OFF", False), (":PROGRAM:NUMBER 40", True), (":PROGRAM:SELECTED:STATE START", False),
    (":SOURCE:CASCADE1:OUTER:PVALUE?", False), (":OUTPUT1:NAME?", False),
])
def test_the_sweep_learns_which_settings_the_simulated_f4t_carries_out(request_text: str, served: bool) -> None:
    assert serves(request_text) is served
