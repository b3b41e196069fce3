"""The simulated ESPEC P300 beyond its profile, where a conversation of tests/protocols/maker_requests.py cannot
show it: its calendar runs on the lab's clock, a locked panel refuses every remote setting and answers every
query, a stalled chamber's constant set point is the one written, and a limit write takes the set point
inside the new limits only as the profile's own write does."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.protocols.chamber_lines import line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.espec_extras import REQUESTS, EspecExtras
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG
from tests.sim.line_client import LineClient, tcp_client


@contextmanager
def espec(**options: object) -> Iterator[tuple[SimulatedLineChamberServer, VirtualLab, LineClient]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedLineChamberServer(lab, line_protocol("espec-p300"), "tcp", **options).start()  # type: ignore[arg-type]
    try:
        with tcp_client(server.endpoint) as client:
            yield server, lab, client
    finally:
        server.stop()


def ask(client: LineClient, request: str) -> str:
    client.send(request.encode() + b"\r\n")
    return client.reply(b"\r\n").removesuffix(b"\r\n").decode()


def test_the_calendar_runs_on_the_labs_clock_from_the_date_and_time_written() -> None:
    with espec() as (_, lab, client):
        assert ask(client, "TIME,23:59:30") == "OK:TIME,23:59:30"
        assert ask(client, "DATE,24.2/28. WED") == "OK:DATE,24.2/28. WED"
        lab.clock.sleep(24 * 3600 + 45)  # a virtual day and 45 s: 2024 is a leap year
        assert (ask(client, "DATE?"), ask(client, "TIME?")) == ("24.03/01", "00:00:15")
        assert ask(client, "DATE,24.2/30. FRI") == "NA:DATA OUT OF RANGE"
        assert ask(client, "TIME,24:00:00") == "NA:DATA OUT OF RANGE"


def test_a_locked_panel_refuses_every_remote_setting_and_answers_queries() -> None:
    with espec() as (server, lab, client):
        server.local_mode = True
        for setting in ("TEMP, H100.0", "HUMI, S50.0", "SET,REF0", "RELAY,ON,1", "KEYPROTECT,ON", "MASK,01000000",
                        "TIME,1:2:3", "IPSET,10.0.0.2,255.0.0.0,10.0.0.1", "POWER,OFF"):
            assert ask(client, setting) == "NA:PROTECT ON", setting
        assert lab.controller_limits_c == (-70.0, 180.0) and lab.thermal.powered
        assert (ask(client, "SET?"), ask(client, "RELAY?"), ask(client, "KEYPROTECT?")) == ("REF9", "0", "OFF")


def test_narrowed_limits_clamp_a_later_set_point_and_the_constant_set_point_is_the_one_shown() -> None:
    with espec(stall_after_s=0.0) as (server, lab, client):
        assert ask(client, "TEMP, S25.0 H30.0 L-10.0") == "OK:TEMP, S25.0 H30.0 L-10.0"
        assert ask(client, "TEMP, S80.0") == "OK:TEMP, S80.0"  # clamped, silently, as the profile's write
        assert server.last_setpoint_c == 30.0
        assert ask(client, "CONSTANT SET?,TEMP") == "30.0,ON"  # what TEMP? shows, though the chamber stalled
        assert ask(client, "TEMP, H20.0 L25.0") == "NA:DATA OUT OF RANGE"  # the lower above the upper
        assert ask(client, "TEMP, Snan") == "NA:CMD ERR"  # a set point that is no number, as before
        assert ask(client, "TEMP, SOFF") == "NA:INVALID REQ"  # temperature control off: not simulated


@pytest.mark.parametrize(("request_text", "answer"), [
    ("MODE,RUN", "NA:PARA ERR"), ("RELAY,ON,", "NA:PARA ERR"), ("MASK,2", "NA:PARA ERR"),
    ("IPSET,1.2.3,255.0.0.0,0.0.0.0", "NA:PARA ERR"), ("SET,REFX", "NA:PARA ERR"), ("FOO?", "NA:CMD ERR"),
])
def test_a_known_command_with_a_parameter_it_cannot_read_is_a_parameter_error(request_text: str, answer: str) -> None:
    with espec() as (_, _, client):
        assert ask(client, request_text) == answer


def test_every_served_pattern_is_answered_by_a_method_or_a_documented_code() -> None:
    codes = {f"NA:{code}" for code in line_protocol("espec-p300").errors} | {"NA:PRGM WRITE ERR-2",
                                                                             "NA:PRGM WRITE ERR-3"}
    for pattern, action, _ in REQUESTS:
        assert action in codes or callable(getattr(EspecExtras, action, None)), pattern.pattern
