"""One pose of a campaign: move the turntable, let it settle, read every DUT at once, store the pose — each
DUT's channels (their means in the channel's unit, standard errors and what they should read: the gravity
its mount sees, the table's rate), and its temperatures against the band its soak settled in."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from accelcal_rig.core.earth import earth_rate_world_dps
from accelcal_rig.core.waits import MOVE_POLL_S, wait_until
from accelcal_rig.engine.acquisition import acquire_together
from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.states import State
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.instruments.interfaces import SampleBlock
from accelcal_rig.parts.part import Channel
from accelcal_rig.plan.steps import Measurement, RateStep
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
    # A turning axis: where it stands is a reading of the moment only.
    run.table.angles_deg = None if any(step.rate_fixture_dps) else measured
    chamber_before = run.chamber.read_temperature_c()  # the alarm is checked once per pose, after it
    # On a turning table a DUT off the axis feels its centripetal acceleration (1.5 g at 5 cm and 1000 °/s): its
    # accelerometer may saturate there, and nothing uses it there.
    turning = any(step.rate_fixture_dps)
    may_saturate = frozenset(c.name for s in run.sensors for c in s.part.channels
                             if turning and c.quantity == "acceleration")
    blocks = run.retrier.call(partial(acquire_together, run.sensors, acquisition.samples_per_pose, run.clock,
                                      acquisition.ranges, may_saturate))
    chamber_after = run.read_chamber_c()
    run.machine.go(State.STORE, step.key)
    gravity_fixture = np.array(step.pose.gravity_fixture)
    at = PoseInstant(step, measured, run.block_s)
    record = PoseRecord(
        step_key=step.key, setpoint_c=step.setpoint_c, pose_number=step.pose.number,
        commanded_angles_deg=commanded, measured_angles_deg=measured, gravity_fixture=gravity_fixture,
        t_start_s=min(b.t_start_s for b in blocks), t_end_s=max(b.t_end_s for b in blocks),
        chamber_temperature_c=(chamber_before, chamber_after),
        duts=[_dut_record(run, i, block, at) for i, block in enumerate(blocks)],
    )
    run.writer.append_pose(record)
    run.report.pose_stored(chamber_after, tuple(float(np.mean(b.temperature_c)) for b in blocks))
    run.events.debug("pose", f"{step.key} stored")
    run.report.publish(run.machine.state)


@dataclass(frozen=True)
class PoseInstant:
    """Where the table was while a record's samples were taken: the step (its pose, its rate), the angles
    read as the samples began, and how long they took."""

    step: Measurement
    measured_angles_deg: np.ndarray
    duration_s: float


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


def _dut_record(run: RunContext, index: int, block: SampleBlock, at: PoseInstant) -> DutPoseRecord:
    """Each of the DUT's channels at the pose (its part's, in order), and its temperatures against the band."""
    sensor, settled_c = run.sensors[index], run.dut.settled_c[index]
    ranges = run.procedure.acquisition.ranges
    channels = {}
    for channel in sensor.part.channels:
        codes = block.codes[channel.name]
        lsb, n = channel.lsb(ranges[channel.name]), codes.shape[0]
        reference = REFERENCES[channel.quantity](run, sensor.serial, channel, at)
        channels[channel.name] = ChannelPoseRecord(codes, codes.mean(axis=0) * lsb,
                                                   codes.std(axis=0, ddof=1) * lsb / np.sqrt(n), reference)
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


def _gravity_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The site's gravity (in standard g) in the DUT's frame: the commanded pose, the nominal mount. A rate
    step's turn about the vertical changes it not; the centripetal acceleration of a DUT off the rate axis is
    not in it (its radius is not known): no accelerometer fit uses a rate step."""
    return run.rig.gravity_g * (run.fixture_to_dut[serial] @ np.array(at.step.pose.gravity_fixture))


def _rate_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The true angular rate in the DUT's frame, °/s: the table's (zero through a pose, the commanded rate
    about the fixture axis through a rate step) and the Earth's as far as the rig config places it."""
    table = np.array(at.step.rate_fixture_dps)
    return run.fixture_to_dut[serial] @ (table + _earth_rate_fixture_dps(run, at))


#: Points over a record's samples at which a turning table's Earth rate is averaged.
_EARTH_POINTS = 64


def _earth_rate_fixture_dps(run: RunContext, at: PoseInstant) -> np.ndarray:
    """The Earth's rate in the fixture frame over the record's samples: nothing where the rig config states no
    latitude; its vertical component always, along "up" whatever turns about the vertical; its horizontal one
    (with a heading) turns with a rate step's axis, averaged over the samples from the angles read as they
    began."""
    if run.rig.latitude_deg is None:
        return np.zeros(3)
    world = earth_rate_world_dps(run.rig.latitude_deg, run.rig.heading_deg)
    angles = np.broadcast_to(np.asarray(at.measured_angles_deg, dtype=float),
                             (_EARTH_POINTS, len(at.measured_angles_deg))).copy()
    if isinstance(at.step, RateStep):
        times = (np.arange(_EARTH_POINTS) + 0.5) / _EARTH_POINTS * at.duration_s
        angles[:, at.step.rate_axis] += at.step.rate_dps * times
    return run.kinematics.world_in_fixture(angles, world).mean(axis=0)


def _field_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The site's magnetic field in the DUT's frame, gauss: the rig config's field at the commanded pose through
    the table's heading and the nominal mount. Without the heading its direction about the vertical is not known
    (taken as 0: only the field's size is then a reference, and the magnetometer's model fits against that)."""
    field = run.rig.magnetic_field
    assert field is not None, "preparation refuses a magnetometer on a rig that states no magnetic_field"
    world = field.world_gauss(run.rig.heading_deg if run.rig.heading_deg is not None else 0.0)
    return run.fixture_to_dut[serial] @ run.kinematics.world_in_fixture(np.array(at.step.pose.angles_deg), world)


#: What a channel should read at a pose, by the quantity it measures.
REFERENCES: dict[str, Callable[[RunContext, str, Channel, PoseInstant], np.ndarray]] = {
    "acceleration": _gravity_reference, "angular rate": _rate_reference, "magnetic field": _field_reference}
#: What of the rig config a quantity's reference needs (a key that must be stated), and what it is.
REFERENCE_NEEDS: dict[str, tuple[str, str]] = {"magnetic field": ("magnetic_field", "the site's magnetic field")}


def _angle_difference(a_deg: np.ndarray, b_deg: np.ndarray) -> np.ndarray:
    """a − b wrapped into [−180, 180)."""
    return (np.asarray(a_deg) - np.asarray(b_deg) + 180.0) % 360.0 - 180.0


MEASURE: StepHandler[Measurement] = MeasureStep()
