"""The runner's account to whoever watches: snapshots that cannot stop a campaign, phases as operators name them."""

from __future__ import annotations

import logging

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.engine.audience import Audience, Reporter
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.states import State
from tests.conftest import TINY_PROCEDURE


def reporter(write, listener, cooldown: bool = False) -> Reporter:
    plan = prepare(write("tiny.yaml", TINY_PROCEDURE)).plan
    return Reporter(Audience(progress=listener), plan, "tiny", VirtualClock(), cooldown, [6], 0)


def test_a_failing_listener_is_reported_once_and_ignored(write, caplog) -> None:
    calls = []

    def broken(progress) -> None:
        calls.append(progress)
        raise RuntimeError("display gone")

    report = reporter(write, broken)
    with caplog.at_level(logging.ERROR, logger="accelcal_rig"):
        for state in (State.RAMP, State.SOAK, State.MOVE):
            report.publish(state)
    assert len(calls) == 1
    assert [r.getMessage() for r in caplog.records] == ["progress display failed, no more progress shown: display gone"]


def test_snapshots_name_the_setpoint_and_the_phase(write) -> None:
    seen = []
    report = reporter(write, seen.append)
    report.publish(State.PREFLIGHT)
    report.begin_setpoint(30.0)
    report.publish(State.SETTLE)
    assert (seen[0].setpoint_c, seen[0].phase) == (None, "preflight")
    assert (seen[1].setpoint_c, seen[1].setpoint_number, seen[1].phase) == (30.0, 1, "poses")
    assert reporter(write, seen.append, cooldown=True).phase_of(State.SETTLE) == "cool"
