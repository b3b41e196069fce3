"""A campaign played in advance against the rig's model: what each step's handler advances when it estimates
its own duration (`engine/estimate.py` walks the plan; each handler in `engine/step_table.py` says how long
its step takes here), and the estimate it adds up to.

The played rig holds the thermal model (the chamber's air, each DUT), the time, the table's angles and the
software ramp once started; each setpoint's time is counted under ramp, soak or poses.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.thermal import ThermalModel
from accelcal_rig.core.waits import MOVE_POLL_S
from accelcal_rig.parts.part import Part, TemperatureFormat, odr_hz_of


@dataclass(frozen=True)
class SetpointEstimate:
    setpoint_c: float
    ramp_s: float
    soak_s: float
    poses_s: float
    n_poses: int
    soak_outcome: str           # "stable"; "timeout" (soak deadline), "ramp timeout" (ramp deadline); "ramp":
                                # the ramp method's poses while ramping (ramp_s: the wait for the ramp)
    settled_dut_c: tuple[float, ...]

    @property
    def total_s(self) -> float:
        return self.ramp_s + self.soak_s + self.poses_s

    @property
    def pose_s(self) -> float:
        """Mean time of one pose at this setpoint."""
        return self.poses_s / self.n_poses if self.n_poses else 0.0


@dataclass(frozen=True)
class DurationEstimate:
    setpoints: tuple[SetpointEstimate, ...]

    @property
    def total_s(self) -> float:
        return sum(s.total_s for s in self.setpoints)

    def remaining_s(self, poses_left: Sequence[int], current: int, phase_elapsed_s: float = 0.0,
                    in_pose_phase: bool = False) -> float:
        """Estimated time left at setpoint index `current`, with `poses_left[k]` poses still to measure at
        setpoint k. The current setpoint's ramp and soak count less `phase_elapsed_s` until its poses
        start; a later setpoint counts its ramp, soak and missing poses, or nothing if none are missing.
        """
        left = 0.0
        for k in range(current, len(self.setpoints)):
            row = self.setpoints[k]
            if k == current:
                left += poses_left[k] * row.pose_s
                if not in_pose_phase:
                    left += max(row.ramp_s + row.soak_s - phase_elapsed_s, 0.0)
            elif poses_left[k]:
                left += row.ramp_s + row.soak_s + poses_left[k] * row.pose_s
        return left


class EstimateEnds(Exception):
    """The engine would abort here (a ramp past its deadline): the estimate stops at this setpoint."""


@dataclass
class SoftwareRampPlayed:
    """The ramp method's software ramp as played: when it started, from where, toward where."""

    started_s: float
    from_c: float
    toward_c: float


@dataclass
class SetpointTally:
    """One setpoint's time so far, by where it goes."""

    setpoint_c: float
    n_poses: int
    ramp_s: float = 0.0
    soak_s: float = 0.0
    poses_s: float = 0.0
    records: int = 0                    #: poses (records) estimated so far at this setpoint
    outcome: str = "ramp"
    settled_dut_c: tuple[float, ...] = ()

    def row(self) -> SetpointEstimate:
        return SetpointEstimate(self.setpoint_c, self.ramp_s, self.soak_s, self.poses_s, self.n_poses, self.outcome,
                                self.settled_dut_c)


@dataclass
class PlayedRig:
    """The rig's model as the plan plays it: each step's handler advances it by its step."""

    procedure: Procedure
    rig: RigConfig
    thermal: ThermalModel
    #: What each DUT's part reads its temperature with (the soak is judged on those readings).
    readers: list[TemperatureFormat]
    speeds_deg_s: np.ndarray
    #: A pose's time besides its travel: the table's settling found half a poll late, the settle time, the samples.
    pose_fixed_s: float
    #: A pose's samples: at the slowest DUT's rate.
    block_s: float
    table_deg: np.ndarray
    t_s: float = 0.0
    software_ramp: SoftwareRampPlayed | None = None
    #: The rate axis's rate (°/s) and the pose it turns in (None: at rest).
    rate_dps: float = 0.0
    turning_in: tuple[float, ...] | None = None
    tally: SetpointTally = field(default_factory=lambda: SetpointTally(float("nan"), 0))

    @classmethod
    def of(cls, procedure: Procedure, rig: RigConfig, parts: list[Part]) -> PlayedRig:
        """The rig at rest before the plan; `parts` are the fixture's DUTs' parts, in its order."""
        sim = rig.simulation
        constants = rig.estimate_thermal()  # the rig's own (thermal:), defaults where it has none
        thermal = ThermalModel(
            ambient_c=constants.room_c, ramp_rate_c_per_s=constants.heating_rate_c_per_min / 60.0,
            cooling_rate_c_per_s=constants.cooling_rate_c_per_min / 60.0,
            chamber_tau_s=constants.chamber_time_constant_min * 60.0,
            dut_tau_s=[constants.fixture_time_constant_min * 60.0] * len(rig.fixture.sensors), self_heating_c=0.0,
            overshoot_fraction=constants.chamber_overshoot_pct / 100.0, cooling_floor_c=constants.cooling_floor_c,
        )
        speeds = np.array([a.speed_deg_s for a in rig.turntable.axes])
        acquisition = procedure.acquisition
        # The table reports in position its settling time after arriving; the engine's position polls find
        # that moment half a polling interval late on average.
        in_position_s = sim.turntable_settle_s + MOVE_POLL_S / 2
        block_s = acquisition.block_s([odr_hz_of(p, acquisition.odr_hz) for p in parts])
        pose_fixed_s = in_position_s + acquisition.settle_s + block_s
        return cls(procedure, rig, thermal, [p.temperature for p in parts], speeds, pose_fixed_s, block_s,
                   np.zeros(len(speeds)))

    def begin_setpoint(self, setpoint_c: float, n_poses: int) -> None:
        self.tally = SetpointTally(setpoint_c, n_poses)

    def travel_to(self, angles_deg: tuple[float, ...]) -> float:
        """The table's travel to `angles_deg` at the axes' speeds (the slowest axis), from where it is."""
        target = np.array(angles_deg)
        travel_s = float(np.max(np.abs(target - self.table_deg) / self.speeds_deg_s))
        self.table_deg = target
        return travel_s

    def wait(self, bucket: str, duration_s: float) -> None:
        """Let `duration_s` pass, counted under `bucket` (ramp, soak or poses)."""
        setattr(self.tally, f"{bucket}_s", getattr(self.tally, f"{bucket}_s") + duration_s)
        self.t_s += duration_s

    def end_setpoint(self) -> SetpointEstimate:
        """The setpoint's row. Poses taken on a running software ramp (no soak held them) let the ramp move
        the chamber meanwhile."""
        tally = self.tally
        if self.software_ramp is not None and tally.outcome == "ramp":
            self.follow_software_ramp(self.t_s - tally.poses_s, self.t_s)
        return tally.row()

    def follow_software_ramp(self, from_s: float, to_s: float) -> None:
        """Move the model's setpoint as the engine's software ramp writes it, every `ramp.update_s`."""
        ramp, settings = self.software_ramp, self.procedure.ramp
        assert ramp is not None and settings is not None
        rate_c_per_s = settings.rate_c_per_min / 60.0
        for t in np.arange(from_s, to_s + 1e-9, settings.update_s):
            travelled = rate_c_per_s * (t - ramp.started_s)
            self.thermal.set_setpoint(float(t), min(ramp.from_c + travelled, ramp.toward_c)
                                      if ramp.toward_c > ramp.from_c else max(ramp.from_c - travelled, ramp.toward_c))
