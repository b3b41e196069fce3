"""One home per kind of step: every kind in the plan's step union has a handler that runs and estimates it,
the estimate counts what the runner waits for, and the safe state is reached once on every way out."""

from __future__ import annotations

import dataclasses
import typing
from pathlib import Path

import pytest

from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.step_table import handler_for
from accelcal_rig.plan.steps import Pose, Step
from tests.conftest import REPO, TINY_PROCEDURE
from tests.engine.test_campaign import events, run_tiny

_VALUES = {"float": 20.0, "str": "T20/x", "bool": True, "int": 1,
           "Pose": Pose(1, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0))}


def _some(kind: type) -> Step:
    """An instance of a step kind, whatever its fields."""
    return kind(**{f.name: _VALUES[str(f.type)] for f in dataclasses.fields(kind)})


@pytest.mark.parametrize("kind", typing.get_args(Step), ids=lambda k: k.__name__)
def test_every_kind_of_step_has_one_handler_that_runs_and_estimates_it(kind: type) -> None:
    handler = handler_for(_some(kind))
    assert callable(handler.run) and callable(handler.estimate)
    assert handler is handler_for(_some(kind))  # one handler per kind, keeping no state of its own


def test_a_kind_of_step_without_a_handler_is_refused() -> None:
    with pytest.raises(AssertionError):
        handler_for(object())  # type: ignore[arg-type]


@pytest.mark.parametrize("procedure", sorted((REPO / "procedures").glob("*.yaml")), ids=lambda p: p.stem)
def test_every_setpoint_of_a_shipped_procedure_is_estimated(procedure: Path) -> None:
    prepared = prepare(procedure)
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    with_poses = [s.setpoint_c for s in prepared.plan.stages if s.records]
    assert [row.setpoint_c for row in estimate.setpoints] == with_poses
    assert all(row.total_s > 0 and row.poses_s > 0 for row in estimate.setpoints)


COLD_THEN_WARM = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [-40, 20]")


def _second_setpoint(write, workdir: Path, dew_point_c: float, frost: str) -> object:
    rig = workdir / "sim.yaml"
    rig.write_text((REPO / "configs" / "sim.yaml").read_text().replace("chamber:\n",
                                                                       f"chamber:\n  dew_point_c: {dew_point_c}\n", 1))
    prepared = prepare(write("p.yaml", COLD_THEN_WARM + frost))
    return estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan).setpoints[1]


@pytest.mark.parametrize(("dew_point_c", "extra_s"), [(12.0, 0.0), (19.0, 3600.0)])
def test_the_estimate_counts_the_wait_for_the_dew_point_margin(write, workdir: Path, dew_point_c: float,
                                                                  extra_s: float) -> None:
    """After −40 °C the poses at 20 °C wait, after the soak, for the DUTs to be 3 °C above the dew point:
    at once for a dew point of 12 °C; never for 19 °C, so the wait's deadline (60 min) is counted."""
    without = _second_setpoint(write, workdir, dew_point_c, "")
    waited = _second_setpoint(write, workdir, dew_point_c, "frost: {dew_point_margin_c: 3}\n")
    assert waited.soak_s - without.soak_s == pytest.approx(extra_s, abs=10.0)  # one soak poll
    assert waited.ramp_s == without.ramp_s and waited.poses_s == without.poses_s


def test_the_safe_state_is_reached_once_when_the_campaign_completes(write, workdir: Path) -> None:
    output, _, error = run_tiny(write, workdir)
    assert error is None
    assert sum(m.startswith("safe state: chamber") for m in events(output, "safe")) == 1


def test_the_safe_state_is_reached_once_when_the_campaign_aborts(write, workdir: Path) -> None:
    def lose_the_table(instruments):
        def gone(*_):
            raise OSError("serial port gone")

        instruments.turntable.move_to = gone

    output, _, error = run_tiny(write, workdir, lose_the_table)
    assert error is not None and "serial port gone" in str(error)
    assert sum(m.startswith("safe state: chamber") for m in events(output, "safe")) == 1
