"""Compile a procedure and rig into the ordered plan of steps the engine executes.

Pure and deterministic: the same files always give the same steps and keys, which is what lets a
campaign file record its plan and a later run recognise it.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Literal

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.plan import schedules
from accelcal_rig.plan.kinematics import TurntableKinematics


@dataclass(frozen=True)
class Pose:
    """One turntable position: `number` is 1-based like the paper's Table 1."""

    number: int
    angles_deg: tuple[float, ...]
    gravity_fixture: tuple[float, float, float]


@dataclass(frozen=True)
class PlanStep:
    key: str
    kind: Literal["soak", "pose"]
    setpoint_c: float
    pose: Pose | None = None


@dataclass(frozen=True)
class Plan:
    setpoints_c: tuple[float, ...]
    poses: tuple[Pose, ...]
    steps: tuple[PlanStep, ...]
    axis_names: tuple[str, ...]

    @property
    def pose_steps(self) -> tuple[PlanStep, ...]:
        return tuple(s for s in self.steps if s.kind == "pose")

    @property
    def fingerprint(self) -> str:
        """SHA-256 over every step's key, setpoint and angles: equal plans, equal fingerprints."""
        rows = [
            [s.key, s.setpoint_c, [round(a, 9) for a in s.pose.angles_deg] if s.pose else None]
            for s in self.steps
        ]
        return hashlib.sha256(json.dumps(rows).encode()).hexdigest()


def setpoint_label(setpoint_c: float) -> str:
    """`-40.0` → `T-40`; used in step keys and soak group names."""
    return f"T{setpoint_c:g}"


def pose_directions(procedure: Procedure, kinematics: TurntableKinematics) -> tuple[np.ndarray, np.ndarray | None]:
    """(gravity directions in the fixture frame, explicit angles or None) for the procedure's schedule."""
    schedule = procedure.schedule
    if schedule.kind == "paper-24":
        return schedules.paper_24(), None
    if schedule.kind == "six-position":
        return schedules.six_position(), None
    if schedule.kind == "sphere":
        return schedules.sphere(schedule.count), None
    if schedule.kind == "tilt":
        return schedules.tilt(np.array(schedule.pitch_roll_deg)), None
    angles = np.array(schedule.angles_deg, dtype=float)
    return kinematics.gravity_in_fixture(angles), angles


def compile_poses(procedure: Procedure, rig: RigConfig) -> tuple[Pose, ...]:
    """Turntable angles for each pose, each solved near the previous one so moves stay short."""
    kinematics = TurntableKinematics(rig.turntable.axes)
    directions, explicit = pose_directions(procedure, kinematics)
    if explicit is not None:
        angles = kinematics.wrap(explicit)
    else:
        angles = np.empty((len(directions), len(kinematics.axes)))
        current = np.zeros(len(kinematics.axes))
        for i, direction in enumerate(directions):
            current = kinematics.solve(direction, current)
            angles[i] = current
    return tuple(
        Pose(i + 1, tuple(round(float(a), 9) + 0.0 for a in row), tuple(float(g) for g in gravity))  # type: ignore[arg-type]
        for i, (row, gravity) in enumerate(zip(angles, directions))
    )


class CooldownPoseMissing(ValueError):
    """The cool-down names a pose the schedule does not have."""


def cooldown_records(procedure: Procedure) -> int:
    """Blocks a cool-down records: one at its start, then one every `record_every_s` for its duration."""
    assert procedure.cooldown is not None
    return int(procedure.cooldown.duration_min * 60.0 // procedure.cooldown.record_every_s) + 1


def compile_plan(procedure: Procedure, rig: RigConfig) -> Plan:
    """Setpoints in procedure order; at each, one soak step then every pose of the schedule. A cool-down
    procedure: its one soak, then its records (`T60/cool0001`, …), all at the pose it holds."""
    poses = compile_poses(procedure, rig)
    names = tuple(a.name for a in rig.turntable.axes)
    if procedure.cooldown is not None:
        if procedure.cooldown.pose > len(poses):
            raise CooldownPoseMissing(f"pose {procedure.cooldown.pose} asked for, the schedule has {len(poses)}")
        held = poses[procedure.cooldown.pose - 1]
        setpoint = procedure.setpoints_c[0]
        label = setpoint_label(setpoint)
        records = [PlanStep(f"{label}/cool{k:04d}", "pose", setpoint, held)
                   for k in range(1, cooldown_records(procedure) + 1)]
        return Plan((setpoint,), (held,), (PlanStep(f"{label}/soak", "soak", setpoint), *records), names)
    width = max(2, len(str(len(poses))))
    steps: list[PlanStep] = []
    for setpoint in procedure.setpoints_c:
        label = setpoint_label(setpoint)
        steps.append(PlanStep(f"{label}/soak", "soak", setpoint))
        steps.extend(PlanStep(f"{label}/pose{p.number:0{width}d}", "pose", setpoint, p) for p in poses)
    return Plan(tuple(procedure.setpoints_c), poses, tuple(steps), names)
