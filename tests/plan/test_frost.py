"""The frost steps woven into a plan: the purge on before going into the cold and off only once a warming
step is over, a dew-point wait before the poses of each warming step, restart entries that assume nothing,
and no change to what the campaign stores."""

from __future__ import annotations

from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.steps import AwaitDewPointMargin, Ramp, SetPurge
from tests.conftest import TINY_PROCEDURE

FROSTY = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [-40, 20, 60, -10, 0]")


def names(steps) -> list[str]:
    return [f"{type(s).__name__}({'on' if s.on else 'off'})" if isinstance(s, SetPurge) else type(s).__name__
            for s in steps]


def test_purge_goes_on_before_the_cold_and_off_after_the_warming_step(write) -> None:
    plan = prepare(write("frost.yaml", FROSTY + "frost: {purge_below_c: 0, dew_point_margin_c: 3}\n")).plan
    assert [names(stage.entry) for stage in plan.stages] == [
        ["SetPurge(on)", "Ramp", "Soak"],                                  # -40
        ["Ramp", "Soak", "AwaitDewPointMargin", "SetPurge(off)"],         # 20: warming out of the cold
        ["Ramp", "Soak", "AwaitDewPointMargin"],                          # 60: warming, purge already off
        ["SetPurge(on)", "Ramp", "Soak"],                                  # -10: cooling into the cold
        ["Ramp", "Soak", "AwaitDewPointMargin", "SetPurge(off)"]]         # 0 (not below 0): warming out


def test_a_run_beginning_anywhere_sets_the_purge_and_past_the_first_setpoint_waits_for_the_dew_point(write) -> None:
    plan = prepare(write("frost.yaml", FROSTY + "frost: {purge_below_c: 0, dew_point_margin_c: 3}\n")).plan
    assert [names(stage.restart_entry) for stage in plan.stages] == [
        ["SetPurge(on)", "Ramp", "Soak"],                                          # the first: nothing before it
        ["SetPurge(on)", "Ramp", "Soak", "AwaitDewPointMargin", "SetPurge(off)"],
        ["SetPurge(off)", "Ramp", "Soak", "AwaitDewPointMargin"],
        ["SetPurge(on)", "Ramp", "Soak", "AwaitDewPointMargin"],                  # cooling, but who knows
        ["SetPurge(on)", "Ramp", "Soak", "AwaitDewPointMargin", "SetPurge(off)"]]


def test_no_purge_steps_where_no_setpoint_is_below_the_threshold(write) -> None:
    plan = prepare(write("warm.yaml", TINY_PROCEDURE.replace("[30]", "[20, 40]") + "frost: {purge_below_c: 0}\n")).plan
    assert not any(isinstance(s, SetPurge) for stage in plan.stages for s in (*stage.entry, *stage.restart_entry))
    assert isinstance(plan.stages[0].entry[0], Ramp)


def test_frost_steps_store_nothing_so_the_plan_fingerprint_is_unchanged(write) -> None:
    plain = prepare(write("plain.yaml", FROSTY)).plan
    frosty = prepare(write("frost.yaml", FROSTY + "frost: {purge_below_c: 5, dew_point_margin_c: 2}\n")).plan
    assert frosty.fingerprint == plain.fingerprint and frosty.records == plain.records
    assert frosty.steps != plain.steps
    assert not any(isinstance(s, (SetPurge, AwaitDewPointMargin)) for s in plain.steps)
