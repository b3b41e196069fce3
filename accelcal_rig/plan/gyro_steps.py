"""A gyroscope's steps at a setpoint: rate steps about each fixture axis in turn (brought to a table axis
with a rate mode), each run of them ended by bringing the axis to rest, and a still noise record.

Two ways bring a fixture axis to a rate axis. The outermost axis, vertical, turns the fixture about the
direction "up" has in the fixture frame whatever the inner axes hold: the pose that puts gravity along the
fixture axis brings it there, and gravity stays constant through the turn (a three-axis table reaches every
fixture axis so). A two-axis table (vertical outer, horizontal inner) brings up only to the fixture directions
square to its inner axis, a plane: its outer axis alone never turns the fixture about the inner axis's own
direction, however the DUTs are mounted (a mount turns the plane, never adds a third direction to it). Its
innermost axis, whose direction is fixed in the fixture frame, turns the fixture about exactly that
direction: where it lies along a fixture axis and has a rate mode and a slip ring, it turns the rate steps
about that axis (gravity then turns about it through the step; no accelerometer fit uses a rate step).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rate_steps import RateSteps
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.plan.kinematics import TurntableKinematics, UnreachablePose
from accelcal_rig.plan.steps import FIXTURE_AXES, NoiseBlock, Pose, RateStep, Step, StopRotation, VerifyRate


class NoRateAxis(ValueError):
    """The rig cannot turn the rate steps a procedure asks for: no axis with a rate mode, or none that a fixture
    axis of `rates.about` can be brought to."""


@dataclass(frozen=True)
class Spin:
    """How the table turns about one fixture axis: the pose it holds, the axis that turns, and the sign that
    takes a rate about the fixture axis to the rate the table axis is commanded (+1 where they point alike)."""

    pose: Pose
    rate_axis: int
    table_sign: float


def rate_axis_candidates(rates: RateSteps, rig: RigConfig) -> list[int]:
    """The table axes a rate step may turn: `rates.axis` alone when named, else every axis with a rate mode,
    outermost first; each checked against its own limits (rate mode, slip ring, rates, acceleration)."""
    axes = rig.turntable.axes
    names = [a.name for a in axes]
    if rates.axis is not None:
        if rates.axis not in names:
            raise NoRateAxis(f"the turntable has no axis {rates.axis!r} (axes: {', '.join(names)})")
        chosen = [names.index(rates.axis)]
    else:
        chosen = [i for i, a in enumerate(axes) if a.has_rate_mode]
        if not chosen:
            raise NoRateAxis("no turntable axis has a rate mode: a rate step needs max_rate_dps and "
                             "max_acceleration_dps2 on the axis that turns (turntable.axes in the rig config)")
    for index in chosen:
        _check_limits(rates, rig, index)
    return chosen


def _check_limits(rates: RateSteps, rig: RigConfig, index: int) -> None:
    axis = rig.turntable.axes[index]
    if not axis.has_rate_mode:
        raise NoRateAxis(f"turntable axis {axis.name} has no rate mode (max_rate_dps and max_acceleration_dps2 "
                         "in the rig config)")
    if not axis.slip_ring:
        raise NoRateAxis(f"turntable axis {axis.name} has no slip ring: a rate step turns it endlessly")
    beyond = [r for r in (*rates.rates_dps, *rates.verify_rates_dps) if r > axis.max_rate_dps]  # type: ignore[operator]
    if beyond:
        raise NoRateAxis(f"{max(beyond):g} °/s is beyond turntable axis {axis.name}'s max_rate_dps "
                         f"{axis.max_rate_dps:g}")
    acceleration = rate_acceleration_dps2(rates, rig, index)
    if acceleration > axis.max_acceleration_dps2:  # type: ignore[operator]
        raise NoRateAxis(f"acceleration_dps2 {acceleration:g} is beyond turntable axis {axis.name}'s "
                         f"max_acceleration_dps2 {axis.max_acceleration_dps2:g}")


def rate_acceleration_dps2(rates: RateSteps, rig: RigConfig, index: int) -> float:
    limit = rig.turntable.axes[index].max_acceleration_dps2
    assert limit is not None
    return float(rates.acceleration_dps2 if rates.acceleration_dps2 is not None else limit)


def spins(rates: RateSteps, rig: RigConfig, start_deg: tuple[float, ...]) -> dict[str, Spin]:
    """How each fixture axis of `rates.about` is turned, each pose solved near the last, by the outermost
    axis that can: a vertical outermost axis at the pose that puts "up" along the fixture axis (gravity stays
    put through the turn); any other at angles of the axes inside it that bring its direction along the fixture
    axis (the innermost: where its fixed direction lies along it). Refused in one line, saying which
    directions each rate axis turns the fixture about, where none reaches it."""
    kinematics = TurntableKinematics(rig.turntable.axes)
    candidates = rate_axis_candidates(rates, rig)
    current = np.array(start_deg, dtype=float)
    found: dict[str, Spin] = {}
    for about in rates.about:
        unit = np.zeros(3)
        unit[FIXTURE_AXES.index(about)] = 1.0
        spin = next((s for index in candidates for s in [_spin(kinematics, index, about, unit, current)] if s), None)
        if spin is None:
            reach = "; ".join(_reach(kinematics, index) for index in candidates)
            raise NoRateAxis(f"rates.about {about}: no turntable axis with a rate mode turns the fixture about its "
                             f"{about} axis ({reach})")
        found[about], current = spin, np.array(spin.pose.angles_deg)
    return found


def _spin(kinematics: TurntableKinematics, index: int, about: str, unit: np.ndarray,
          near_deg: np.ndarray) -> Spin | None:
    direction = np.array(kinematics.axes[index].axis, dtype=float)
    if index == 0 and abs(abs(direction[2]) - 1.0) <= 1e-9:  # up, turned about the vertical, stays up
        sign = float(np.sign(direction[2]))
        try:
            angles = kinematics.solve(sign * unit, near_deg)
        except UnreachablePose:
            return None
        return Spin(_pose(about, angles, sign * unit), index, 1.0)
    for table_sign in (1.0, -1.0):
        try:
            angles = kinematics.solve_turn(index, table_sign * unit, near_deg)
        except UnreachablePose:
            continue
        return Spin(_pose(about, angles, kinematics.gravity_in_fixture(angles)), index, table_sign)
    return None


def _reach(kinematics: TurntableKinematics, index: int) -> str:
    """Which fixture directions turning one axis turns the fixture about, for a refusal: its own (the
    innermost), those square to the axis inside it (a vertical outermost axis of a two-axis table), or
    what the axes inside it reach."""
    axes = kinematics.axes
    name = axes[index].name
    if index == len(axes) - 1:
        return f"{name} turns it only about {np.round(axes[index].axis, 4).tolist()}"
    if index == len(axes) - 2:
        inner = np.array(axes[index + 1].axis, dtype=float)
        angle = float(np.degrees(np.arccos(np.clip(inner @ np.array(axes[index].axis, dtype=float), -1.0, 1.0))))
        return (f"{name} turns it only about directions {angle:g}° from {axes[index + 1].name}'s "
                f"{np.round(inner, 4).tolist()}")
    return f"{name} turns it about the directions its inner axes' limits reach"


def _pose(about: str, angles_deg: np.ndarray, up: np.ndarray) -> Pose:
    """The pose a spin starts from: numbered 1, 2, 3 for x, y, z, with gravity in the fixture frame there."""
    up = np.round(np.asarray(up, dtype=float), 12) + 0.0
    return Pose(FIXTURE_AXES.index(about) + 1, tuple(round(float(a), 9) + 0.0 for a in angles_deg),
                (float(up[0]), float(up[1]), float(up[2])))


def rate_steps(label: str, setpoint_c: float, rates: RateSteps, rig: RigConfig, spun: dict[str, Spin],
               calibrate: bool, verify: bool) -> list[Step]:
    """At one setpoint: about each axis, its rates from the most negative to the most positive (the table
    never stops in between), then the axis brought to rest."""
    chosen = [(r, False) for r in rates.rates_dps if calibrate] + [(r, True) for r in rates.verify_rates_dps if verify]
    signed = sorted([(s * r, checked) for r, checked in chosen for s in (-1.0, 1.0)])
    steps: list[Step] = []
    for about in rates.about:
        spin = spun[about]
        for rate, checked in signed:
            kind = VerifyRate if checked else RateStep
            key = f"{label}/{'verify-' if checked else ''}rate_{about}{'p' if rate > 0 else 'm'}{abs(rate):g}"
            steps.append(kind(key, setpoint_c, spin.pose, about, rate, spin.rate_axis, spin.table_sign))
        if signed:
            acceleration = rate_acceleration_dps2(rates, rig, spin.rate_axis)
            steps.append(StopRotation(setpoint_c, spin.rate_axis, acceleration, spin.table_sign * signed[-1][0]))
    return steps


def noise_blocks(label: str, setpoint_c: float, procedure: Procedure, pose: Pose) -> list[NoiseBlock]:
    """The still noise record: `procedure.noise_blocks()` blocks at the pose."""
    count = procedure.noise_blocks()
    width = max(3, len(str(count)))
    return [NoiseBlock(f"{label}/noise{k:0{width}d}", setpoint_c, pose, k) for k in range(1, count + 1)]
