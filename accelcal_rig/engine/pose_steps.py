"""One pose of a campaign: move the turntable, let it settle, read every DUT at once, store the pose — each
DUT's channels (their means in the channel's unit, standard errors and what they should read: their quantity's
reference, engine/references.py), and its temperatures against the band its soak settled in."""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from accelcal_rig.core.waits import MOVE_POLL_S, wait_until
from accelcal_rig.engine.acquisition import acquire_together
from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.references import REFERENCES, SATURATES_TURNING, PoseInstant
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.states import State
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.engine.step_ranges import set_ranges, step_ranges
from accelcal_rig.instruments.interfaces import SampleBlock
from accelcal_rig.plan.steps import Measurement
from accelcal_rig.store.records import ChannelPoseRecord, DutPoseRecord, PoseRecord

#: A move's deadline is 1.5 × its travel time at the configured speeds plus this margin.
MOVE_MARGIN_S = 30.0


class MeasureStep:
    """A calibration or verification pose."""

    def run(self, step: Measurement, run: RunContext) -> None:
        measure(step, run)

    def estimate(self, step: Measurement, played: PlayedRig) -> None:
        """The table's travel from where it is, then its settling, the settle time and the samples."""
        played.wait("poses", played.travel_to(step.pose.angles_deg) + played.pose_fixed_s)


def measure(step: Measurement, run: RunContext) -> None:
    """Move, settle, acquire every DUT at once, store the pose."""
    if step.setpoint_c != run.table.setpoint_c:
        run.table.angles_deg, run.table.setpoint_c = None, step.setpoint_c
    commanded = np.array(step.pose.angles_deg)
    run.machine.go(State.MOVE, step.key)
    move_to(run, commanded)
    run.machine.go(State.SETTLE, step.key)
    run.clock.sleep(run.procedure.acquisition.settle_s)
    acquire_and_store(step, run, commanded)


def acquire_and_store(step: Measurement, run: RunContext, commanded: np.ndarray) -> None:
    """Read the table's angles, acquire every DUT at once, store the record with each channel's reference."""
    acquisition = run.procedure.acquisition
    run.machine.go(State.ACQUIRE, step.key)
    measured = run.turntable.read_angles_deg()
    read_at_s = run.clock.now()
    # A turning axis: where it stands is a reading of the moment only.
    run.table.angles_deg = None if any(step.rate_fixture_dps) else measured
    chamber_before = run.chamber.read_temperature_c()  # the alarm is checked once per pose, after it
    # On a turning table some channels may saturate (engine/references.py says which): nothing uses them there.
    turning = any(step.rate_fixture_dps)
    may_saturate = frozenset(c.name for s in run.sensors for c in s.part.channels
                             if turning and c.quantity in SATURATES_TURNING)
    ranges = step_ranges(acquisition, step)
    set_ranges(run, ranges)
    blocks = run.retrier.call(partial(acquire_together, run.sensors, acquisition.samples_per_pose, run.clock,
                                      ranges, may_saturate))
    chamber_after = run.read_chamber_c()
    run.machine.go(State.STORE, step.key)
    gravity_fixture = np.array(step.pose.gravity_fixture)
    at = PoseInstant(step, measured, run.block_s)
    record = PoseRecord(
        step_key=step.key, setpoint_c=step.setpoint_c, pose_number=step.pose.number,
        commanded_angles_deg=commanded, measured_angles_deg=measured, gravity_fixture=gravity_fixture,
        t_start_s=min(b.t_start_s for b in blocks), t_end_s=max(b.t_end_s for b in blocks),
        chamber_temperature_c=(chamber_before, chamber_after),
        duts=[_dut_record(run, i, block, replace(at, lead_s=block.t_start_s - read_at_s), ranges)
              for i, block in enumerate(blocks)],
    )
    run.writer.append_pose(record)
    run.report.pose_stored(chamber_after, tuple(float(np.mean(b.temperature_c)) for b in blocks))
    run.events.debug("pose", f"{step.key} stored")
    run.report.publish(run.machine.state)


def move_to(run: RunContext, commanded: np.ndarray) -> None:
    """Move the table to `commanded` and wait until it is there, settled, within the position tolerance."""
    turntable = run.turntable
    current = turntable.read_angles_deg() if run.table.angles_deg is None else run.table.angles_deg
    speeds = np.array([a.speed_deg_s for a in run.rig.turntable.axes])
    travel_s = float(np.max(np.abs(commanded - current) / speeds))
    turntable.move_to(commanded)
    run.clock.sleep(travel_s)  # no axis arrives sooner at its configured speed: poll only after
    tolerance = run.rig.turntable.position_tolerance_deg

    def arrived() -> bool:
        if not turntable.in_position():
            return False
        error = _angle_difference(turntable.read_angles_deg(), commanded)
        return bool(np.all(np.abs(error) <= tolerance))

    wait_until(run.clock, arrived, timeout_s=0.5 * travel_s + MOVE_MARGIN_S, poll_s=MOVE_POLL_S,
               what=f"turntable ({turntable.endpoint}) reaching {np.round(commanded, 3).tolist()}°")


def _dut_record(run: RunContext, index: int, block: SampleBlock, at: PoseInstant,
                ranges: dict[str, float]) -> DutPoseRecord:
    """Each of the DUT's channels at the pose (its part's, in order, at the step's ranges; a range other than the
    campaign's recorded with it), and its temperatures against the band."""
    sensor, settled_c = run.sensors[index], run.dut.settled_c[index]
    campaign_ranges = run.procedure.acquisition.ranges
    channels = {}
    for channel in sensor.part.channels:
        codes = block.codes[channel.name]
        range_ = ranges[channel.name]
        lsb, n = channel.lsb(range_), codes.shape[0]
        reference = REFERENCES[channel.quantity](run, sensor.serial, channel, at)
        channels[channel.name] = ChannelPoseRecord(codes, codes.mean(axis=0) * lsb,
                                                   codes.std(axis=0, ddof=1) * lsb / np.sqrt(n), reference,
                                                   None if range_ == campaign_ranges[channel.name] else range_)
    band = run.procedure.soak.band_c
    in_band = bool(np.all(np.abs(np.array(block.temperature_c) - settled_c) <= band))
    if not in_band and not run.dut.moving:
        before, after = block.temperature_c
        run.events.warning("pose", f"sensor {sensor.serial}: temperature {before:.2f}/{after:.2f} °C left the "
                                   f"±{band:g} °C band around {settled_c:.2f} °C")
    return DutPoseRecord(
        serial=sensor.serial, channels=channels, temperature_c=block.temperature_c, temperature_in_band=in_band,
        truth=run.truth.block_truth(sensor.serial, block) if run.truth is not None else None,
    )


def _angle_difference(a_deg: np.ndarray, b_deg: np.ndarray) -> np.ndarray:
    """a − b wrapped into [−180, 180)."""
    return (np.asarray(a_deg) - np.asarray(b_deg) + 180.0) % 360.0 - 180.0


MEASURE: StepHandler[Measurement] = MeasureStep()
