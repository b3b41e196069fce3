"""A gyroscope's steps: a rate step turns the table's rate axis at a constant rate and takes a record while
it turns; a stop brings the axis to rest; a noise record's blocks follow one another at a still pose.

A rate step starts from the rate the axis turns at (the compiler orders each axis's rates so the table never
stops between them), waits for the new rate at the step's acceleration and `rates.settle_s`, checks the rate
the table reads back, then acquires. Nothing but the table's own limits (instruments/limits.py) stands
between a command and the wire, and the run's safe state brings every axis to rest.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.core.waits import MOVE_POLL_S, wait_until
from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.pose_steps import MOVE_MARGIN_S, acquire_and_store, measure, move_to
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.states import State
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import ConstantRateRotation
from accelcal_rig.plan.gyro_steps import rate_acceleration_dps2
from accelcal_rig.plan.steps import NoiseBlock, RateStep, StopRotation

#: A rate read back is the commanded one within this share of it, beyond the table's stated accuracy and
#: 4 × its stability, plus RATE_FLOOR_DPS.
RATE_FLOOR_DPS = 0.01


def rate_table(run: RunContext) -> ConstantRateRotation:
    """The turntable as a rate table, or a fault naming it (its driver's profile has no rate commands)."""
    turntable = run.turntable
    if not isinstance(turntable, ConstantRateRotation):
        raise InstrumentError(f"turntable ({turntable.endpoint}): its driver has no rate mode (a rate step needs "
                              "a profile with rate commands)")
    return turntable


def rate_tolerance_dps(run: RunContext, rate_dps: float) -> float:
    """How far the rate read back may be from the commanded one: the table's stated accuracy and 4 × its
    stability of the rate, and a floor."""
    table = run.rig.turntable
    share = ((table.rate_accuracy_pct or 0.0) + 4.0 * (table.rate_stability_pct or 0.0)) / 100.0
    return abs(rate_dps) * share + RATE_FLOOR_DPS


class RateStepHandler:
    def run(self, step: RateStep, run: RunContext) -> None:
        table = rate_table(run)
        procedure_rates = run.procedure.rates
        assert procedure_rates is not None
        acceleration = rate_acceleration_dps2(procedure_rates, run.rig, step.rate_axis)
        commanded = np.array(step.pose.angles_deg)
        if run.table.turning_in != step.pose.angles_deg:  # at rest, or turning about another fixture axis
            if run.table.rate_dps:
                stop_turning(run, step.rate_axis, acceleration)
            run.machine.go(State.MOVE, step.key)
            if step.setpoint_c != run.table.setpoint_c:
                run.table.angles_deg, run.table.setpoint_c = None, step.setpoint_c
            move_to(run, commanded)
        run.machine.go(State.SETTLE, step.key)
        rate = step.table_rate_dps
        table.rotate_at(step.rate_axis, rate, acceleration)
        change_s = abs(rate - run.table.rate_dps) / acceleration
        run.table.rate_dps, run.table.turning_in, run.table.angles_deg = rate, step.pose.angles_deg, None
        run.clock.sleep(change_s + procedure_rates.settle_s)
        tolerance = rate_tolerance_dps(run, rate)
        wait_until(run.clock, lambda: abs(table.read_rate_deg_s(step.rate_axis) - rate) <= tolerance,
                   timeout_s=0.5 * change_s + MOVE_MARGIN_S, poll_s=MOVE_POLL_S,
                   what=f"turntable ({run.turntable.endpoint}) axis {run.rig.turntable.axes[step.rate_axis].name} "
                        f"turning at {rate:g} °/s (±{tolerance:.3g})")
        acquire_and_store(step, run, commanded)

    def estimate(self, step: RateStep, played: PlayedRig) -> None:
        """The travel to the pose unless the axis already turns in it, the change of rate, the settle time and
        the samples."""
        procedure_rates = played.procedure.rates
        assert procedure_rates is not None
        acceleration = rate_acceleration_dps2(procedure_rates, played.rig, step.rate_axis)
        travel_s = 0.0
        if played.turning_in != step.pose.angles_deg:
            travel_s = abs(played.rate_dps) / acceleration + played.travel_to(step.pose.angles_deg)
            played.rate_dps = 0.0
        change_s = abs(step.table_rate_dps - played.rate_dps) / acceleration
        played.rate_dps, played.turning_in = step.table_rate_dps, step.pose.angles_deg
        played.wait("poses", travel_s + change_s + procedure_rates.settle_s + MOVE_POLL_S / 2
                    + played.block_s)


def stop_turning(run: RunContext, axis: int, acceleration_dps2: float) -> None:
    """Hold the rate axis and wait until it reads back at rest; its angle is then read afresh."""
    table = rate_table(run)
    table.hold(axis)
    stop_s = abs(run.table.rate_dps) / acceleration_dps2
    run.clock.sleep(stop_s)
    wait_until(run.clock, lambda: abs(table.read_rate_deg_s(axis)) <= RATE_FLOOR_DPS,
               timeout_s=0.5 * stop_s + MOVE_MARGIN_S, poll_s=MOVE_POLL_S,
               what=f"turntable ({run.turntable.endpoint}) axis {run.rig.turntable.axes[axis].name} at rest")
    run.table.rate_dps, run.table.turning_in, run.table.angles_deg = 0.0, None, None


def bring_rate_axes_to_rest(run: RunContext) -> None:
    """Before anything moves, every run: each axis the rig gives a rate mode read back, and one still turning
    (a run that stopped mid-step whose safe state could not reach the table, a controller left turning by
    hand) held until it is at rest, said in the event log. The run's bookkeeping starts from rest."""
    turntable = run.turntable
    if not isinstance(turntable, ConstantRateRotation):
        return
    for index, axis in enumerate(run.rig.turntable.axes):
        if axis.max_acceleration_dps2 is None:
            continue
        rate = turntable.read_rate_deg_s(index)
        if abs(rate) > RATE_FLOOR_DPS:
            run.events.warning("preflight", f"turntable ({turntable.endpoint}) axis {axis.name} turning at {rate:g} °/s "
                                            "before the run: brought to rest first")
            run.table.rate_dps = rate
            stop_turning(run, index, axis.max_acceleration_dps2)
    run.table.rate_dps, run.table.turning_in = 0.0, None


class StopRotationHandler:
    def run(self, step: StopRotation, run: RunContext) -> None:
        if run.table.rate_dps or run.table.turning_in is not None:
            stop_turning(run, step.rate_axis, step.acceleration_dps2)

    def estimate(self, step: StopRotation, played: PlayedRig) -> None:
        played.wait("poses", abs(played.rate_dps) / step.acceleration_dps2 + MOVE_POLL_S / 2)
        played.rate_dps, played.turning_in = 0.0, None


class NoiseBlockHandler:
    """The first block (or the first of a resumed run) moves to the pose and settles as a pose does; each
    later one follows at once, so the blocks make one record with no gap but the store's."""

    def run(self, step: NoiseBlock, run: RunContext) -> None:
        held = run.table.angles_deg is not None and np.array_equal(run.table.angles_deg, step.pose.angles_deg)
        if step.number == 1 or not held or run.table.setpoint_c != step.setpoint_c:
            measure(step, run)
            run.table.angles_deg = np.array(step.pose.angles_deg)
            return
        acquire_and_store(step, run, np.array(step.pose.angles_deg))
        run.table.angles_deg = np.array(step.pose.angles_deg)

    def estimate(self, step: NoiseBlock, played: PlayedRig) -> None:
        if step.number == 1:
            played.wait("poses", played.travel_to(step.pose.angles_deg) + played.pose_fixed_s)
        else:
            played.wait("poses", played.block_s)


RATE_STEP: StepHandler[RateStep] = RateStepHandler()
STOP_ROTATION: StepHandler[StopRotation] = StopRotationHandler()
NOISE_BLOCK: StepHandler[NoiseBlock] = NoiseBlockHandler()
