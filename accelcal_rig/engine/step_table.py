"""One table of step kinds: each kind of plan step has one handler, which runs it on the rig *and* estimates
its duration against the rig's model. The runner (engine/campaign.py) and `rig plan`'s estimate
(engine/estimate.py) both find a step's handler here, so no step can be run without being estimated, and
the type checker proves (`assert_never`) that every kind of step in `plan.steps.Step` has a handler.

A new kind of step: a type in plan/steps.py, emitted by the compiler, a handler class with `run` and
`estimate` (engine/step_handler.py), and a case below.
"""

from __future__ import annotations

from typing import Any, assert_never

from accelcal_rig.engine.cooldown_steps import COOLDOWN_RECORD
from accelcal_rig.engine.frost_steps import AWAIT_DEW_POINT_MARGIN, SET_PURGE
from accelcal_rig.engine.pose_steps import MEASURE
from accelcal_rig.engine.rate_steps import NOISE_BLOCK, RATE_STEP, STOP_ROTATION
from accelcal_rig.engine.setpoint_check_steps import CHECK_SETPOINT
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.engine.thermal_steps import ADVANCE_RAMP, RAMP, RAMP_SEGMENT, SOAK, START_SOFTWARE_RAMP
from accelcal_rig.plan.steps import (
    AdvanceRamp,
    AwaitDewPointMargin,
    CheckSetpoint,
    CooldownRecord,
    MeasurePose,
    NoiseBlock,
    Ramp,
    RampSegment,
    RateStep,
    SetPurge,
    Soak,
    StartSoftwareRamp,
    Step,
    StopRotation,
    VerifyPose,
    VerifyRate,
)


def handler_for(step: Step) -> StepHandler[Any]:
    """The handler of a step's kind."""
    match step:
        case Ramp():
            return RAMP
        case Soak():
            return SOAK
        case StartSoftwareRamp():
            return START_SOFTWARE_RAMP
        case RampSegment():
            return RAMP_SEGMENT
        case AdvanceRamp():
            return ADVANCE_RAMP
        case MeasurePose() | VerifyPose():
            return MEASURE
        case RateStep() | VerifyRate():
            return RATE_STEP
        case StopRotation():
            return STOP_ROTATION
        case NoiseBlock():
            return NOISE_BLOCK
        case CooldownRecord():
            return COOLDOWN_RECORD
        case SetPurge():
            return SET_PURGE
        case AwaitDewPointMargin():
            return AWAIT_DEW_POINT_MARGIN
        case CheckSetpoint():
            return CHECK_SETPOINT
        case _:
            assert_never(step)
