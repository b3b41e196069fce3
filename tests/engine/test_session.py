"""The session around the runner: a stop or a failure that comes between the campaign file's creation and the runner's
first step still ends in the safe state, recorded in the file."""

from __future__ import annotations

import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

from accelcal_rig.assembly import AssembledRig, InProcessRig
from accelcal_rig.core.signals import TerminationRequested
from accelcal_rig.engine.connection import GuardedRig
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.session import run_campaign
from accelcal_rig.errors import CampaignAborted
from accelcal_rig.sim.devices import build_simulated_rig
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE
from tests.engine.test_campaign import events


class StoppingRig:
    """A connected rig on which the stop arrives just as the run wraps its devices: the file exists."""

    def __init__(self, rig: AssembledRig, stop: BaseException) -> None:
        self.instruments, self.clock, self._stop = rig.instruments, rig.clock, stop

    def guarded(self, events: EventLog) -> GuardedRig:
        raise self._stop


@dataclass
class StopsBeforeTheFirstStep:
    inner: InProcessRig
    stop: BaseException
    dry_run: bool = True

    @contextmanager
    def __call__(self, seed: int, clock_start_s: float = 0.0) -> Iterator[StoppingRig]:
        with self.inner(seed, clock_start_s) as rig:
            yield StoppingRig(rig, self.stop)


@pytest.mark.parametrize(("stop", "reason"), [(KeyboardInterrupt(), "interrupted by operator (Ctrl-C)"),
                                               (TerminationRequested(), "terminated by signal (SIGTERM)"),
                                               (RuntimeError("wrapping failed"), "RuntimeError: wrapping failed")])
def test_a_stop_before_the_first_step_ends_safe_and_recorded(write, workdir: Path, stop, reason) -> None:
    prepared = prepare(write("tiny.yaml", TINY_PROCEDURE))
    output = workdir / "run.h5"
    connect = StopsBeforeTheFirstStep(InProcessRig(prepared.rig.model, prepared.procedure.model, build_simulated_rig),
                                      stop)
    with pytest.raises(CampaignAborted, match=re.escape(reason)):
        run_campaign(prepared, output, connect, seed=1, overwrite=False)
    campaign = load_campaign(output)
    assert campaign.state == "aborted" and campaign.abort_reason == reason and not campaign.poses
    safe = events(output, "safe")
    assert any("to 23 °C" in m for m in safe) and any("turntable" in m and "stop" in m for m in safe)
    assert sum("standby" in m for m in safe) == 4
    assert f"campaign aborted before its first step: {reason}" in events(output, "fault")
