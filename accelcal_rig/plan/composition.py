"""What a plan's measurements are, in one phrase for the run's header: how many of each kind (calibration poses,
verification poses, rate steps, noise blocks, cool-down records) at how many setpoints. A plan's setpoints do not
all hold the same poses (verification-only setpoints hold none of the calibration schedule), so "14 setpoints × 24
poses" is not what it measures."""

from __future__ import annotations

from collections import Counter

from accelcal_rig.plan.compile import Plan
from accelcal_rig.plan.steps import CooldownRecord, Measurement

#: How each kind of stored measurement is named, in the order named.
KIND_NAMES = {"pose": "calibration", "verify": "verification", "rate": "rate steps",
              "verify-rate": "verification rate steps", "noise": "noise blocks"}


def _kind(step: Measurement) -> str:
    return "cool-down records" if isinstance(step, CooldownRecord) else KIND_NAMES.get(step.stored_kind, step.stored_kind)


def plan_composition(plan: Plan) -> str:
    """`432 poses: 264 calibration (24 × 11 setpoints) + 168 verification (12 × 14 setpoints)`."""
    by_kind: dict[str, Counter[float]] = {}
    for step in plan.pose_steps:
        by_kind.setdefault(_kind(step), Counter())[step.setpoint_c] += 1
    parts = []
    for name, per_setpoint in by_kind.items():
        total, setpoints = sum(per_setpoint.values()), len(per_setpoint)
        counts = set(per_setpoint.values())
        where = (f"{counts.pop()} × {setpoints} setpoint{'s' if setpoints != 1 else ''}" if len(counts) == 1
                 else f"at {setpoints} setpoints")
        parts.append(f"{total} {name} ({where})")
    return f"{len(plan.pose_steps)} poses: " + " + ".join(parts)
