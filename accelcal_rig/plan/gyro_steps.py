"""A gyroscope's steps at a setpoint: rate steps about each fixture axis in turn (brought to the table's rate
axis), each run of them ended by bringing the axis to rest, and a still noise record.

The rate axis is the outermost axis the rig config gives a rate mode, and it must be vertical: turning it
then turns the fixture about the direction "up" has in the fixture frame, whatever the inner axes hold, so a
fixture axis is brought to it by the pose that puts gravity along that axis (a multi-axis table does it by
itself), and gravity stays constant through the turn.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rate_steps import RateSteps
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.plan.kinematics import TurntableKinematics, UnreachablePose
from accelcal_rig.plan.steps import FIXTURE_AXES, NoiseBlock, Pose, RateStep, Step, StopRotation, VerifyRate


class NoRateAxis(ValueError):
    """The rig cannot turn the rate steps a procedure asks for: no axis with a rate mode, or not vertical."""


def rate_axis_index(rates: RateSteps, rig: RigConfig) -> int:
    """The table axis that turns: `rates.axis`, else the outermost with a rate mode; refused unless it has a
    rate mode, is outermost with a vertical direction, and is allowed to turn endlessly (a slip ring)."""
    axes = rig.turntable.axes
    names = [a.name for a in axes]
    if rates.axis is not None:
        if rates.axis not in names:
            raise NoRateAxis(f"the turntable has no axis {rates.axis!r} (axes: {', '.join(names)})")
        index = names.index(rates.axis)
    else:
        with_rate = [i for i, a in enumerate(axes) if a.has_rate_mode]
        if not with_rate:
            raise NoRateAxis("no turntable axis has a rate mode: a rate step needs max_rate_dps and "
                             "max_acceleration_dps2 on the axis that turns (turntable.axes in the rig config)")
        index = with_rate[0]
    axis = axes[index]
    if not axis.has_rate_mode:
        raise NoRateAxis(f"turntable axis {axis.name} has no rate mode (max_rate_dps and max_acceleration_dps2 "
                         "in the rig config)")
    if index != 0 or abs(abs(axis.axis[2]) - 1.0) > 1e-9:
        raise NoRateAxis(f"turntable axis {axis.name} turns the rate steps only as the outermost axis with a "
                         "vertical direction (axis: [0, 0, 1]); this rig's is "
                         f"{'not outermost' if index else 'not vertical'}")
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
    return index


def rate_acceleration_dps2(rates: RateSteps, rig: RigConfig, index: int) -> float:
    limit = rig.turntable.axes[index].max_acceleration_dps2
    assert limit is not None
    return float(rates.acceleration_dps2 if rates.acceleration_dps2 is not None else limit)


def rate_poses(rates: RateSteps, rig: RigConfig, start_deg: tuple[float, ...]) -> dict[str, Pose]:
    """The pose that brings each fixture axis of `rates.about` to the rate axis (numbered 1, 2, 3 for x, y,
    z), each solved near the last."""
    kinematics = TurntableKinematics(rig.turntable.axes)
    sign = float(np.sign(rig.turntable.axes[rate_axis_index(rates, rig)].axis[2]))
    poses: dict[str, Pose] = {}
    current = np.array(start_deg, dtype=float)
    for about in rates.about:
        up = np.zeros(3)
        up[FIXTURE_AXES.index(about)] = sign  # the rate axis along `about`: up is along it (or against it)
        try:
            current = kinematics.solve(up, current)
        except UnreachablePose as exc:
            raise NoRateAxis(f"rates.about {about}: the fixture's {about} axis cannot be brought to the rate axis: "
                             f"{exc}") from None
        poses[about] = Pose(FIXTURE_AXES.index(about) + 1, tuple(round(float(a), 9) + 0.0 for a in current),
                            (float(up[0]), float(up[1]), float(up[2])))
    return poses


def rate_steps(label: str, setpoint_c: float, rates: RateSteps, rig: RigConfig, poses: dict[str, Pose],
               calibrate: bool, verify: bool) -> list[Step]:
    """At one setpoint: about each axis, its rates from the most negative to the most positive (the table
    never stops in between), then the axis brought to rest."""
    index = rate_axis_index(rates, rig)
    acceleration = rate_acceleration_dps2(rates, rig, index)
    chosen = [(r, False) for r in rates.rates_dps if calibrate] + [(r, True) for r in rates.verify_rates_dps if verify]
    signed = sorted([(s * r, checked) for r, checked in chosen for s in (-1.0, 1.0)])
    steps: list[Step] = []
    for about in rates.about:
        for rate, checked in signed:
            kind = VerifyRate if checked else RateStep
            key = f"{label}/{'verify-' if checked else ''}rate_{about}{'p' if rate > 0 else 'm'}{abs(rate):g}"
            steps.append(kind(key, setpoint_c, poses[about], about, rate, index))
        if signed:
            steps.append(StopRotation(setpoint_c, index, acceleration, signed[-1][0]))
    return steps


def noise_blocks(label: str, setpoint_c: float, procedure: Procedure, pose: Pose) -> list[NoiseBlock]:
    """The still noise record: `procedure.noise_blocks()` blocks at the pose."""
    count = procedure.noise_blocks()
    width = max(3, len(str(count)))
    return [NoiseBlock(f"{label}/noise{k:0{width}d}", setpoint_c, pose, k) for k in range(1, count + 1)]
