"""The frost steps a procedure asks for, woven into its stages: the dry-air purge switched where the
setpoints cross `frost.purge_below_c`, and a dew-point wait before the poses of every warming step.

Neither stores a record, so a plan's fingerprint does not change with them (and a campaign recorded
before them still resumes)."""

from __future__ import annotations

from dataclasses import replace

from accelcal_rig.config.procedure import Frost
from accelcal_rig.plan.steps import AwaitDewPointMargin, SetPurge, Stage, Step


def with_frost_steps(stages: list[Stage], frost: Frost) -> list[Stage]:
    """Each stage's entry led by a purge switch where its state changes (a restart entry always sets it:
    a resumed run does not know it), and ended by a dew-point wait when the stage warms from the last."""
    woven = []
    purging: bool | None = None  # unknown before the first stage
    previous_c: float | None = None
    for stage in stages:
        lead: tuple[Step, ...] = ()
        restart_lead: tuple[Step, ...] = ()
        if frost.purge_below_c is not None:
            wanted = stage.setpoint_c < frost.purge_below_c
            restart_lead = (SetPurge(stage.setpoint_c, wanted),)
            lead = restart_lead if wanted != purging else ()
            purging = wanted
        warming = previous_c is not None and stage.setpoint_c > previous_c
        tail: tuple[Step, ...] = ((AwaitDewPointMargin(stage.setpoint_c),)
                                  if frost.dew_point_margin_c is not None and warming else ())
        woven.append(replace(stage, entry=(*lead, *stage.entry, *tail),
                             restart_entry=(*restart_lead, *stage.restart_entry, *tail)))
        previous_c = stage.setpoint_c
    return woven
