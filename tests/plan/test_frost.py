"""The frost steps woven into a plan: the purge switched where the setpoints cross its threshold, a dew-point
wait before the poses of each warming step, and no change to what the campaign stores."""

from __future__ import annotations

from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.steps import AwaitDewPointMargin, Ramp, SetPurge, Soak
from tests.conftest import TINY_PROCEDURE

FROSTY = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [-40, 20, 60, -10, 0]")


def test_purge_switches_where_the_threshold_is_crossed_and_waits_follow_warming_soaks(write) -> None:
    plan = prepare(write("frost.yaml", FROSTY + "frost: {purge_below_c: 0, dew_point_margin_c: 3}\n")).plan
    entries = [[type(step).__name__ for step in stage.entry] for stage in plan.stages]
    assert entries == [["SetPurge", "Ramp", "Soak"],                          # -40: on
                       ["SetPurge", "Ramp", "Soak", "AwaitDewPointMargin"],   # 20: off, warming
                       ["Ramp", "Soak", "AwaitDewPointMargin"],               # 60: still off, warming
                       ["SetPurge", "Ramp", "Soak"],                          # -10: on, cooling
                       ["SetPurge", "Ramp", "Soak", "AwaitDewPointMargin"]]   # 0: off (not below 0), warming
    assert [s.on for stage in plan.stages for s in stage.entry if isinstance(s, SetPurge)] == [True, False, True, False]
    # A run beginning at any setpoint sets the purge first, whatever the last run left it at.
    for stage in plan.stages:
        first = stage.restart_entry[0]
        assert isinstance(first, SetPurge) and first.on == (stage.setpoint_c < 0)
        assert isinstance(stage.restart_entry[1], Ramp) and isinstance(stage.restart_entry[2], Soak)
        assert (AwaitDewPointMargin(stage.setpoint_c) in stage.restart_entry) == (
            AwaitDewPointMargin(stage.setpoint_c) in stage.entry)


def test_frost_steps_store_nothing_so_the_plan_fingerprint_is_unchanged(write) -> None:
    plain = prepare(write("plain.yaml", FROSTY)).plan
    frosty = prepare(write("frost.yaml", FROSTY + "frost: {purge_below_c: 5, dew_point_margin_c: 2}\n")).plan
    assert frosty.fingerprint == plain.fingerprint and frosty.records == plain.records
    assert frosty.steps != plain.steps
    assert not any(isinstance(s, (SetPurge, AwaitDewPointMargin)) for s in plain.steps)
