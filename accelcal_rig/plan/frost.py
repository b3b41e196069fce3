"""The frost steps a procedure asks for, woven into its stages: the dry-air purge switched where the
setpoints cross `frost.purge_below_c`, and a dew-point wait before the poses of every warming step.

The purge goes on before the ramp down into the cold, and off only once a warming step is over (after its
soak and dew-point wait): the cold fixture warms in dry air. A run that begins at a setpoint (a resume,
or after a skipped soak) does not know what the last run left, so its restart entry sets the purge and,
past the first setpoint, waits for the dew point whatever the direction.

Neither step stores a record, so a plan's fingerprint does not change with them (and a campaign recorded
before them still resumes)."""

from __future__ import annotations

from dataclasses import replace

from accelcal_rig.config.procedure import Frost
from accelcal_rig.plan.steps import AwaitDewPointMargin, SetPurge, Stage, Step


def with_frost_steps(stages: list[Stage], frost: Frost) -> list[Stage]:
    threshold = frost.purge_below_c
    purging_needed = threshold is not None and any(stage.setpoint_c < threshold for stage in stages)
    woven = []
    purging: bool | None = None  # unknown before the first stage
    previous_c: float | None = None
    for stage in stages:
        warming = previous_c is not None and stage.setpoint_c > previous_c
        wait: tuple[Step, ...] = (AwaitDewPointMargin(stage.setpoint_c),) if frost.dew_point_margin_c is not None else ()
        lead: tuple[Step, ...] = ()
        tail: tuple[Step, ...] = wait if warming else ()
        restart_lead: tuple[Step, ...] = ()
        restart_tail: tuple[Step, ...] = wait if previous_c is not None or warming else ()
        if purging_needed:
            assert threshold is not None
            wanted = stage.setpoint_c < threshold
            out_of_the_cold = purging is True and not wanted  # warming from below the threshold
            if out_of_the_cold:  # dry air until the step is over, then off
                tail = (*tail, SetPurge(stage.setpoint_c, False))
            elif wanted != purging:
                lead = (SetPurge(stage.setpoint_c, wanted),)
            restart_lead = (SetPurge(stage.setpoint_c, wanted or out_of_the_cold),)
            if out_of_the_cold:
                restart_tail = (*restart_tail, SetPurge(stage.setpoint_c, False))
            purging = wanted
        woven.append(replace(stage, entry=(*lead, *stage.entry, *tail),
                             restart_entry=(*restart_lead, *stage.restart_entry, *restart_tail)))
        previous_c = stage.setpoint_c
    return woven
