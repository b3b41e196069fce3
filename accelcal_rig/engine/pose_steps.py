"""One pose of a campaign: move the turntable, let it settle, read every DUT at once, store the pose — each
DUT's mean in g, its standard error, its temperatures against the band its soak settled in, and the
gravity its mount sees."""

from __future__ import annotations

from functools import partial

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.waits import MOVE_POLL_S, wait_until
from accelcal_rig.engine.acquisition import acquire_together
from accelcal_rig.engine.audience import Reporter
from accelcal_rig.engine.connection import GuardedRig
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.states import State, StateMachine
from accelcal_rig.engine.thermal_steps import ThermalSteps
from accelcal_rig.instruments.interfaces import SampleBlock
from accelcal_rig.plan.steps import Measurement
from accelcal_rig.store.records import DutPoseRecord, PoseRecord
from accelcal_rig.store.writer import CampaignWriter

#: A move's deadline is 1.5 × its travel time at the configured speeds plus this margin.
MOVE_MARGIN_S = 30.0


class PoseSteps:
    def __init__(self, procedure: Procedure, rig: RigConfig, guarded: GuardedRig, clock: Clock, events: EventLog,
                 writer: CampaignWriter, machine: StateMachine, report: Reporter, thermal: ThermalSteps) -> None:
        self.procedure, self.rig = procedure, rig
        self.retrier = guarded.retrier
        instruments = guarded.instruments
        self.chamber, self.turntable, self.sensors = instruments.chamber, instruments.turntable, instruments.sensors
        self.truth = instruments.truth
        self.clock, self.events, self.writer, self.machine, self.report = clock, events, writer, machine, report
        self.thermal = thermal
        #: Fixture frame → each DUT's frame (the inverse of its mounting), by serial.
        self._fixture_to_dut = {s.serial: Rotation.from_euler("xyz", s.mount_euler_deg, degrees=True).inv().as_matrix()
                                for s in rig.fixture.sensors}
        #: The table's angles as last read, and the setpoint they were read at: the first move at each
        #: setpoint reads them afresh (hours of soak: the table may have been moved, or have drifted).
        self._table_angles_deg: np.ndarray | None = None
        self._table_setpoint_c: float | None = None

    def measure(self, step: Measurement) -> None:
        """Move, settle, acquire every DUT at once, store the pose."""
        if step.setpoint_c != self._table_setpoint_c:
            self._table_angles_deg, self._table_setpoint_c = None, step.setpoint_c
        commanded = np.array(step.pose.angles_deg)
        self.machine.go(State.MOVE, step.key)
        self._move(commanded)
        self.machine.go(State.SETTLE, step.key)
        self.clock.sleep(self.procedure.acquisition.settle_s)
        self.machine.go(State.ACQUIRE, step.key)
        measured = self._table_angles_deg = self.turntable.read_angles_deg()
        chamber_before = self.chamber.read_temperature_c()  # the alarm is checked once per pose, after it
        n = self.procedure.acquisition.samples_per_pose
        blocks = self.retrier.call(partial(acquire_together, self.sensors, n, self.clock,
                                           self.procedure.acquisition.range_g))
        chamber_after = self.thermal.read_chamber_c()
        self.machine.go(State.STORE, step.key)
        gravity_fixture = np.array(step.pose.gravity_fixture)
        record = PoseRecord(
            step_key=step.key, setpoint_c=step.setpoint_c, pose_number=step.pose.number,
            commanded_angles_deg=commanded, measured_angles_deg=measured, gravity_fixture=gravity_fixture,
            t_start_s=min(b.t_start_s for b in blocks), t_end_s=max(b.t_end_s for b in blocks),
            chamber_temperature_c=(chamber_before, chamber_after),
            duts=[self._dut_record(i, block, gravity_fixture) for i, block in enumerate(blocks)],
        )
        self.writer.append_pose(record)
        self.report.poses_done += 1
        self.report.poses_left[self.report.setpoint_index] -= 1
        self.report.chamber_c = chamber_after
        self.report.dut_c = tuple(float(np.mean(b.temperature_c)) for b in blocks)
        self.events.debug("pose", f"{step.key} stored")
        self.report.publish(self.machine.state)

    def _move(self, commanded: np.ndarray) -> None:
        current = self.turntable.read_angles_deg() if self._table_angles_deg is None else self._table_angles_deg
        speeds = np.array([a.speed_deg_s for a in self.rig.turntable.axes])
        travel_s = float(np.max(np.abs(commanded - current) / speeds))
        self.turntable.move_to(commanded)
        self.clock.sleep(travel_s)  # no axis arrives sooner at its configured speed: poll only after
        tolerance = self.rig.turntable.position_tolerance_deg

        def arrived() -> bool:
            if not self.turntable.in_position():
                return False
            error = _angle_difference(self.turntable.read_angles_deg(), commanded)
            return bool(np.all(np.abs(error) <= tolerance))

        wait_until(self.clock, arrived, timeout_s=0.5 * travel_s + MOVE_MARGIN_S, poll_s=MOVE_POLL_S,
                   what=f"turntable ({self.turntable.endpoint}) reaching {np.round(commanded, 3).tolist()}°")

    def _dut_record(self, index: int, block: SampleBlock, gravity_fixture: np.ndarray) -> DutPoseRecord:
        sensor = self.sensors[index]
        lsb = sensor.part.lsb_g(self.procedure.acquisition.range_g)
        codes = block.codes_xyz
        n = codes.shape[0]
        mean_g = codes.mean(axis=0) * lsb
        stderr_g = codes.std(axis=0, ddof=1) * lsb / np.sqrt(n)
        band = self.procedure.soak.band_c
        in_band = bool(np.all(np.abs(np.array(block.temperature_c) - self.thermal.settled_dut_c[index]) <= band))
        if not in_band and not self.thermal.temperature_moving:
            before, after = block.temperature_c
            self.events.warning("pose", f"sensor {sensor.serial}: temperature {before:.2f}/{after:.2f} °C left the "
                                        f"±{band:g} °C band around {self.thermal.settled_dut_c[index]:.2f} °C")
        return DutPoseRecord(
            serial=sensor.serial, raw_codes=codes, mean_g=mean_g, stderr_g=stderr_g,
            temperature_c=block.temperature_c,
            gravity_reference_g=self.rig.gravity_g * (self._fixture_to_dut[sensor.serial] @ gravity_fixture),
            temperature_in_band=in_band,
            truth=self.truth.block_truth(sensor.serial, block) if self.truth is not None else None,
        )


def _angle_difference(a_deg: np.ndarray, b_deg: np.ndarray) -> np.ndarray:
    """a − b wrapped into [−180, 180)."""
    return (np.asarray(a_deg) - np.asarray(b_deg) + 180.0) % 360.0 - 180.0
