"""How long a campaign will take, before it starts: the plan's steps played against the rig's model, each
by its own handler (engine/step_table.py), the one that runs it.

The chamber ramps up and down at the rig's own measured rates (cooling slower towards a floor), its air lags
and overshoots, and the DUTs lag the air as the slowest measured DUT does: the rig config's `thermal:`
section, which `rig characterise` fits to a finished campaign, defaults where it has none (config/rig.py,
`RigConfig.estimate_thermal`; the same thermal model a dry run's lab uses). The ramp and soak are polled exactly as the engine
polls them, through the same soak detector, fed with what each DUT's part reads (engine/soak_estimate.py).
Each pose costs its turntable travel at the axes' speeds, the table's settling
(`simulation.turntable_settle_s`) and half a position poll, the procedure's settle time and the samples at
the data rate. Instrument communication time is not included (a few milliseconds per exchange on a real
rig, none in virtual time).
"""

from __future__ import annotations

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.engine.played import DurationEstimate, EstimateEnds, PlayedRig, SetpointEstimate
from accelcal_rig.engine.step_table import handler_for
from accelcal_rig.parts.registry import part
from accelcal_rig.plan.compile import Plan
from accelcal_rig.plan.steps import Measurement

__all__ = ["DurationEstimate", "SetpointEstimate", "estimate_duration"]


def estimate_duration(procedure: Procedure, rig: RigConfig, plan: Plan) -> DurationEstimate:
    """Each setpoint with poses, its entry and body played in order; a ramp past its deadline ends it."""
    played = PlayedRig.of(procedure, rig, [part(s.part) for s in rig.fixture.sensors])
    rows = []
    for stage in plan.stages:
        n_poses = sum(1 for s in stage.body if isinstance(s, Measurement))
        if not n_poses:
            continue
        played.begin_setpoint(stage.setpoint_c, n_poses)
        try:
            for step in (*stage.entry, *stage.body):
                handler_for(step).estimate(step, played)
        except EstimateEnds:
            rows.append(played.tally.row())
            break
        rows.append(played.end_setpoint())
    return DurationEstimate(tuple(rows))
