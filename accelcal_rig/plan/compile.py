"""Compile a procedure and rig into the ordered plan of steps the engine executes.

Pure and deterministic: the same files always give the same steps and keys, which is what lets a
campaign file record its plan and a later run recognise it.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.config.schedule import Schedule
from accelcal_rig.plan import schedules
from accelcal_rig.plan.frost import with_frost_steps
from accelcal_rig.plan.gyro_steps import Spin, noise_blocks, rate_steps, spins
from accelcal_rig.plan.kinematics import TurntableKinematics
from accelcal_rig.plan.steps import (
    AdvanceRamp,
    CheckSetpoint,
    CooldownRecord,
    Measurement,
    MeasurePose,
    Pose,
    Ramp,
    RampSegment,
    Record,
    Soak,
    Stage,
    StartSoftwareRamp,
    Step,
    VerifyPose,
)


@dataclass(frozen=True)
class Plan:
    """`setpoints_c`: every stage's, in the order run (calibration and verification setpoints); `poses`: the
    calibration schedule's, `verification_poses` the verification schedule's."""

    setpoints_c: tuple[float, ...]
    poses: tuple[Pose, ...]
    stages: tuple[Stage, ...]
    axis_names: tuple[str, ...]
    verification_poses: tuple[Pose, ...] = ()

    @cached_property
    def steps(self) -> tuple[Step, ...]:
        """The program of a run that starts at the beginning."""
        return tuple(step for stage in self.stages for step in (*stage.entry, *stage.body))

    @cached_property
    def records(self) -> tuple[Record, ...]:
        """Every record the campaign may store, in plan order: what its file lists as the plan."""
        return tuple(record for stage in self.stages for record in stage.records)

    @cached_property
    def pose_steps(self) -> tuple[Measurement, ...]:
        return tuple(s for s in self.records if isinstance(s, Measurement))

    @cached_property
    def fingerprint(self) -> str:
        """SHA-256 over every record's key, setpoint and angles: equal plans, equal fingerprints."""
        rows = [
            [s.key, s.setpoint_c, [round(a, 9) for a in s.pose.angles_deg] if isinstance(s, Measurement) else None]
            for s in self.records
        ]
        return hashlib.sha256(json.dumps(rows).encode()).hexdigest()


def setpoint_label(setpoint_c: float) -> str:
    """`-40.0` → `T-40`; used in step keys and soak group names."""
    return f"T{setpoint_c:g}"


def pose_directions(schedule: Schedule, kinematics: TurntableKinematics) -> tuple[np.ndarray, np.ndarray | None]:
    """(gravity directions in the fixture frame, explicit angles or None) for a schedule."""
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


def compile_poses(schedule: Schedule, rig: RigConfig, start_deg: tuple[float, ...] | None = None) -> tuple[Pose, ...]:
    """Turntable angles for each pose, each solved near the previous one (the first near `start_deg`, else
    zero) so moves stay short; in the schedule's `order` (as listed, or the shortest travel)."""
    kinematics = TurntableKinematics(rig.turntable.axes)
    directions, explicit = pose_directions(schedule, kinematics)
    if explicit is not None:
        angles = kinematics.wrap(explicit)
        order = list(range(len(directions)))
    else:
        current = np.zeros(len(kinematics.axes)) if start_deg is None else np.array(start_deg)
        if getattr(schedule, "order", "as-listed") == "shortest-travel":
            order, angles = _shortest_travel(directions, current, kinematics,
                                             np.array([a.speed_deg_s for a in rig.turntable.axes]))
        else:
            order, angles = list(range(len(directions))), np.empty((len(directions), len(kinematics.axes)))
            for i, direction in enumerate(directions):
                current = kinematics.solve(direction, current)
                angles[i] = current
    return tuple(  # in the order visited, each numbered as its schedule lists it
        Pose(i + 1, tuple(round(float(a), 9) + 0.0 for a in angles[k]),
             tuple(float(g) for g in directions[i]))  # type: ignore[arg-type]
        for k, i in enumerate(order)
    )


def _shortest_travel(directions: np.ndarray, start_deg: np.ndarray, kinematics: TurntableKinematics,
                     speeds_deg_s: np.ndarray) -> tuple[list[int], np.ndarray]:
    """(schedule indices in the order visited, their angles in that order): from where the table stands,
    always the pose it reaches soonest (its slowest axis's travel at its speed), each solved near the last."""
    left, order, angles = list(range(len(directions))), [], []
    current = start_deg
    while left:
        reached = [kinematics.solve(directions[i], current) for i in left]
        nearest = int(np.argmin([np.max(np.abs(a - current) / speeds_deg_s) for a in reached]))
        order.append(left.pop(nearest))
        current = reached[nearest]
        angles.append(current)
    return order, np.array(angles)


class CooldownPoseMissing(ValueError):
    """The cool-down names a pose the schedule does not have."""


def cooldown_records(procedure: Procedure) -> int:
    """Blocks a cool-down records: one at its start, then one every `record_every_s` for its duration."""
    assert procedure.cooldown is not None
    return int(procedure.cooldown.duration_min * 60.0 // procedure.cooldown.record_every_s) + 1


def compile_plan(procedure: Procedure, rig: RigConfig) -> Plan:
    """Setpoints in procedure order; at each, the steps that bring the rig there, then every pose of the
    schedule and the verification poses; verification setpoints where the sequence passes them. A cool-down
    procedure: one setpoint, then its records (`T60/cool0001`, …) at the pose it holds."""
    poses = compile_poses(procedure.schedule, rig)
    names = tuple(a.name for a in rig.turntable.axes)
    if procedure.cooldown is not None:
        if procedure.cooldown.pose > len(poses):
            raise CooldownPoseMissing(f"pose {procedure.cooldown.pose} asked for, the schedule has {len(poses)}")
        held = next(p for p in poses if p.number == procedure.cooldown.pose)
        setpoint = procedure.setpoints_c[0]
        label = setpoint_label(setpoint)
        soaked = _ramp_and_soak(setpoint)
        records = tuple(CooldownRecord(f"{label}/cool{k:04d}", setpoint, held, k)
                        for k in range(1, cooldown_records(procedure) + 1))
        stage = with_frost_steps([Stage(setpoint, soaked, records, soaked)], procedure.frost)
        return Plan((setpoint,), (held,), tuple(stage), names)
    verify = procedure.verify
    checks = compile_poses(verify.schedule, rig, poses[-1].angles_deg) if verify is not None else ()
    if checks:
        _check_verification_is_new(poses, checks)
    width = max(2, len(str(len(poses))))
    spun = spins(procedure.rates, rig, (checks or poses)[-1].angles_deg) if procedure.rates is not None else {}
    setpoints = tuple(procedure.setpoints_c)
    bidirectional = procedure.method == "ramp" and procedure.ramp is not None and procedure.ramp.bidirectional
    if bidirectional:  # and back, half-way between the setpoints
        setpoints += tuple(0.5 * (a + b) for a, b in zip(setpoints[::-1], setpoints[-2::-1]))
    stages = []
    entry: tuple[Step, ...]
    restart: tuple[Step, ...]
    for index, setpoint in enumerate(setpoints):
        label = setpoint_label(setpoint)
        measure: list[MeasurePose | VerifyPose] = [MeasurePose(f"{label}/pose{p.number:0{width}d}", setpoint, p) for p in poses]
        if procedure.method == "ramp":
            entry, restart = _ramp_method_entries(setpoints, index, len(procedure.setpoints_c) - 1)
        else:
            entry = restart = _ramp_and_soak(setpoint)
        at_rest = any(isinstance(step, Soak) for step in entry)
        verified = verify is not None and verify.at_setpoints and (at_rest or verify.on_ramp)
        if verified and procedure.method == "ramp" and at_rest:
            # A ramp soaks only at its ends, and its DUTs still creep towards the air there: the checks first, so
            # the calibration poses after them reach further and the calibrated range holds every check (one
            # past it is compensated at the range's end, off by the slope times the overshoot: issue 39).
            measure[:0] = _verification(setpoint, checks)
        elif verified:
            measure.extend(_verification(setpoint, checks))
        gyroscope = _gyroscope(procedure, rig, setpoint, spun, poses, calibrate=True, verify=verified, noise=at_rest)
        if procedure.method == "ramp":  # the ramp's setpoint written before each step taken on it
            body: tuple[Step, ...] = tuple(step for m in (*measure, *gyroscope) for step in (AdvanceRamp(setpoint), m))
        else:
            body = (*measure, *gyroscope)
        if at_rest and procedure.early_check.action != "none":
            body = _checked_after_poses(body, setpoint)
        stages.append(Stage(setpoint, entry, body, restart))
        if verify is not None and index + 1 < len(setpoints):
            passed = _passed_between(setpoint, setpoints[index + 1], verify.setpoints_c, stages)
            stages.extend(Stage(v, _ramp_and_soak(v), (*_verification(v, checks),
                                                       *_gyroscope(procedure, rig, v, spun, poses, False, True)),
                                _ramp_and_soak(v))
                          for v in passed)
    stages = with_frost_steps(stages, procedure.frost)
    return Plan(tuple(s.setpoint_c for s in stages), poses, tuple(stages), names, checks)


def _checked_after_poses(body: tuple[Step, ...], setpoint_c: float) -> tuple[Step, ...]:
    """The body with the early check right after its last calibration pose (before the verification poses and
    a gyroscope's steps: a DUT it drops is known before them). Only where the DUTs were soaked: poses taken
    on a ramp drift with their temperature, which no fit of one setpoint follows."""
    last = max(i for i, step in enumerate(body) if isinstance(step, MeasurePose))
    return (*body[:last + 1], CheckSetpoint(setpoint_c), *body[last + 1:])


def _gyroscope(procedure: Procedure, rig: RigConfig, setpoint_c: float, spun: dict[str, Spin],
               poses: tuple[Pose, ...], calibrate: bool, verify: bool, noise: bool = True) -> list[Step]:
    """A gyroscope's steps after the poses: the rate steps (calibration, verification or both), then, at a
    calibration setpoint where the DUTs are soaked (`noise`: not a band taken on a ramp, whose moving
    temperature a still record's bias would follow), the still noise record."""
    label = setpoint_label(setpoint_c)
    steps: list[Step] = []
    if procedure.rates is not None:
        steps += rate_steps(label, setpoint_c, procedure.rates, rig, spun, calibrate, verify)
    if procedure.noise is not None and calibrate and noise:
        held = next(p for p in poses if p.number == procedure.noise.pose)
        steps += noise_blocks(label, setpoint_c, procedure, held)
    return steps


def _verification(setpoint_c: float, checks: tuple[Pose, ...]) -> list[VerifyPose]:
    width = max(2, len(str(len(checks))))
    label = setpoint_label(setpoint_c)
    return [VerifyPose(f"{label}/verify{p.number:0{width}d}", setpoint_c, p) for p in checks]


def _passed_between(from_c: float, to_c: float, candidates_c: list[float], stages: list[Stage]) -> list[float]:
    """The verification setpoints strictly between two calibration setpoints not visited yet, in the order
    the chamber passes them."""
    visited = {s.setpoint_c for s in stages}
    inside = [v for v in candidates_c if min(from_c, to_c) < v < max(from_c, to_c) and v not in visited]
    return sorted(inside, reverse=to_c < from_c)


class VerificationSeenByFit(ValueError):
    """A verification pose has a calibration pose's orientation."""


#: Orientations closer than this are the same pose to the fit.
SAME_POSE_DEG = 1.0


def _check_verification_is_new(poses: tuple[Pose, ...], checks: tuple[Pose, ...]) -> None:
    calibration = np.array([p.gravity_fixture for p in poses])
    verification = np.array([p.gravity_fixture for p in checks])
    cosine = np.clip(verification @ calibration.T, -1.0, 1.0)
    close = np.argwhere(np.degrees(np.arccos(cosine)) < SAME_POSE_DEG)
    if len(close):
        check, pose = close[0]
        raise VerificationSeenByFit(f"verification pose {checks[check].number} has the orientation of calibration "
                                    f"pose {poses[pose].number} (within {SAME_POSE_DEG:g}°): verification poses must be ones the "
                                    "fit does not see")


def _ramp_and_soak(setpoint_c: float) -> tuple[Ramp, Soak]:
    return Ramp(setpoint_c), Soak(f"{setpoint_label(setpoint_c)}/soak", setpoint_c)


def _ramp_method_entries(setpoints_c: tuple[float, ...], index: int,
                         turn: int) -> tuple[tuple[Step, ...], tuple[Step, ...]]:
    """(entry, restart entry) of the ramp method's `index`-th setpoint. The first soaks, its poses and checks
    at rest; the software ramp starts after them, the second's poses begin half-way from the first, and
    each later one's half-way from the previous setpoint, on the ramp; the one at `turn`
    (the last setpoint) holds until the DUTs, lagging the air, have caught up, so the calibrated range
    reaches it. A bidirectional ramp goes on from there, back towards the first, its bands half-way between
    the setpoints, the last of them taken where the ramp stops."""
    setpoint = setpoints_c[index]
    last = setpoints_c[-1]
    ramp, soak = _ramp_and_soak(setpoint)
    toward = setpoints_c[turn] if index < turn else last
    start = (ramp, soak, StartSoftwareRamp(setpoint, toward))
    if index == 0:
        return (ramp, soak), (ramp, soak)
    # The ramp leaves the first setpoint once its poses are taken: as the second one begins.
    leaving: tuple[Step, ...] = (StartSoftwareRamp(setpoints_c[0], setpoints_c[turn]),) if index == 1 else ()
    if index == turn:
        return (*leaving, RampSegment(setpoint, setpoint), soak), (ramp, soak)
    halfway = RampSegment(setpoint, 0.5 * (setpoints_c[index - 1] + setpoint))
    if leaving:
        return (*leaving, halfway), start
    if index == turn + 1:  # the way back begins after the turn's poses
        return (StartSoftwareRamp(setpoints_c[turn], last), halfway), start
    if index == len(setpoints_c) - 1:
        return (RampSegment(setpoint, setpoint),), (ramp, soak)
    return (halfway,), start
