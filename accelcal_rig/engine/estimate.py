"""How long a campaign will take, before it starts: the engine's own waits played against the rig's model.

The chamber ramps at the rig's ramp rate and its air lags with `simulation.chamber_time_constant_min`;
each DUT lags the air with `simulation.fixture_time_constant_min` (the same thermal model a dry run uses,
so set those two to a real rig's measured values). The ramp and soak are polled exactly as the engine
polls them, through the same soak detector, fed with what each DUT's part reads (an ADXL355: 0.11 °C steps, with noise):
the soak is the median over `SOAK_DRAWS` draws of that noise, since the band is a few steps wide and the
noise moves the moment it is met by minutes. Each pose costs its turntable travel at the axes' speeds, the
table's settling (`simulation.turntable_settle_s`) and half a position poll, the procedure's settle time
and the samples at the data rate. Instrument communication
time is not included (a few milliseconds per exchange on a real rig, none in virtual time).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.thermal import TEMPERATURE_READ_NOISE_C, ThermalModel
from accelcal_rig.core.waits import MOVE_POLL_S
from accelcal_rig.engine.soak import first_stable_poll, settled_at
from accelcal_rig.parts.part import TemperatureFormat
from accelcal_rig.parts.registry import part
from accelcal_rig.plan.compile import Plan
from accelcal_rig.plan.steps import Measurement, Ramp, RampSegment, Soak, StartSoftwareRamp

#: Draws of the temperature reading noise over which the soak duration is a median.
SOAK_DRAWS = 9


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


def estimate_duration(procedure: Procedure, rig: RigConfig, plan: Plan) -> DurationEstimate:
    sim = rig.simulation
    soak = procedure.soak
    acquisition = procedure.acquisition
    serials = [s.serial for s in rig.fixture.sensors]
    thermal = ThermalModel(
        ambient_c=sim.ambient_c, ramp_rate_c_per_s=rig.chamber.ramp_rate_c_per_min / 60.0,
        chamber_tau_s=sim.chamber_time_constant_min * 60.0, dut_tau_s=sim.fixture_time_constants_s(serials),
        self_heating_c=sim.self_heating_c, overshoot_fraction=sim.chamber_overshoot_pct / 100.0,
        cooling_floor_c=sim.cooling_floor_c, slot_offset_per_c=sim.slot_offsets_per_c(len(serials)),
    )
    readers = [part(s.part).temperature for s in rig.fixture.sensors]
    speeds = np.array([a.speed_deg_s for a in rig.turntable.axes])
    # The table reports in position its settling time after arriving; the engine's position polls find
    # that moment half a polling interval late on average.
    in_position_s = sim.turntable_settle_s + MOVE_POLL_S / 2
    pose_fixed_s = in_position_s + acquisition.settle_s + acquisition.samples_per_pose / acquisition.odr_hz
    table_deg = np.zeros(len(speeds))
    t = 0.0
    rows = []
    ramp: tuple[float, float, float] | None = None  # the software ramp once started: (t, from °C, toward °C)
    rate_c_per_s = procedure.ramp.rate_c_per_min / 60.0 if procedure.ramp is not None else 0.0
    for stage in plan.stages:
        angles = np.array([s.pose.angles_deg for s in stage.body if isinstance(s, Measurement) and s.pose is not None])
        if not len(angles):
            continue
        path = np.vstack([table_deg, angles])
        travel_s = np.max(np.abs(np.diff(path, axis=0)) / speeds, axis=1)
        table_deg = angles[-1]
        poses_s = float(travel_s.sum()) + len(angles) * pose_fixed_s
        setpoint = stage.setpoint_c
        ramp_s = soak_s = 0.0
        outcome, settled = "ramp", ()  # type: tuple[str, tuple[float, ...]]
        for step in stage.entry:  # the plan is the program: its steps, played against the model
            if isinstance(step, Ramp):
                ramp = None
                thermal.set_setpoint(t, setpoint)
                ramp_start = t
                ramp_deadline = t + soak.ramp_timeout_factor * abs(setpoint - thermal.air_c(t)) / (
                    rig.chamber.ramp_rate_c_per_min / 60.0) + soak.ramp_timeout_margin_min * 60.0
                while abs(thermal.air_c(t) - setpoint) > soak.chamber_tolerance_c and t < ramp_deadline:
                    t = min(t + soak.poll_s, ramp_deadline)
                ramp_s += t - ramp_start
                if abs(thermal.air_c(t) - setpoint) > soak.chamber_tolerance_c:
                    rows.append(SetpointEstimate(setpoint, ramp_s, 0.0, 0.0, len(angles), "ramp timeout", ()))
                    return DurationEstimate(tuple(rows))  # the engine would abort here
            elif isinstance(step, Soak):
                soak_s, outcome, settled = _soak(thermal, procedure, setpoint, t, readers)
                t += soak_s
            elif isinstance(step, StartSoftwareRamp):
                ramp = (t, step.setpoint_c, step.toward_c)
            elif isinstance(step, RampSegment) and ramp is not None:
                wait_s = max(ramp[0] + abs(step.until_c - ramp[1]) / rate_c_per_s - t, 0.0)
                _follow_software_ramp(thermal, procedure, ramp, t, t + wait_s)
                t += wait_s
                ramp_s += wait_s
        if procedure.cooldown is not None:  # the records come on a schedule from the first
            poses_s = float(travel_s[0]) + (len(angles) - 1) * procedure.cooldown.record_every_s + pose_fixed_s
        if ramp is not None and outcome == "ramp":
            _follow_software_ramp(thermal, procedure, ramp, t, t + poses_s)
        rows.append(SetpointEstimate(setpoint, ramp_s, soak_s, poses_s, len(angles), outcome, settled))
        t += poses_s
    return DurationEstimate(tuple(rows))


def _follow_software_ramp(thermal: ThermalModel, procedure: Procedure, ramp: tuple[float, float, float],
                          from_s: float, to_s: float) -> None:
    """Move the model's setpoint as the engine's software ramp writes it, every `ramp.update_s`."""
    assert procedure.ramp is not None
    rate_c_per_s = procedure.ramp.rate_c_per_min / 60.0
    t0, start_c, toward_c = ramp
    for t in np.arange(from_s, to_s + 1e-9, procedure.ramp.update_s):
        travelled = rate_c_per_s * (t - t0)
        thermal.set_setpoint(float(t), min(start_c + travelled, toward_c) if toward_c > start_c
                             else max(start_c - travelled, toward_c))


def _soak(thermal: ThermalModel, procedure: Procedure, setpoint_c: float, t_reached_s: float,
          readers: list[TemperatureFormat]) -> tuple[float, str, tuple[float, ...]]:
    """(soak duration s, outcome, settled DUT temperatures °C): the median over noise draws of the soak."""
    soak = procedure.soak
    n_polls = int(math.ceil(soak.timeout_min * 60.0 / soak.poll_s)) + 1
    t = np.minimum(t_reached_s + soak.poll_s * np.arange(n_polls), t_reached_s + soak.timeout_min * 60.0)
    ahead = copy.deepcopy(thermal)  # looks ahead to the deadline; the campaign's model stays at t_reached
    air, dut = np.empty(n_polls), np.empty((n_polls, len(thermal.dut_tau_s)))
    for k, ti in enumerate(t.tolist()):  # the model only advances: every query at one time before the next
        air[k], dut[k] = ahead.air_c(ti), ahead.duts_c(ti)
    rng = np.random.default_rng(0)
    outcomes = []
    for _ in range(SOAK_DRAWS):
        read = _as_read(dut + rng.normal(0.0, TEMPERATURE_READ_NOISE_C, dut.shape), readers)
        stable = first_stable_poll(soak, setpoint_c, t_reached_s, t, air, read)
        if stable is not None:
            outcomes.append((float(t[stable] - t_reached_s), "stable", settled_at(soak, t, read, stable)))
        else:
            outcomes.append((float(t[-1] - t_reached_s), "timeout", settled_at(soak, t, read, n_polls - 1)))
    soak_s, outcome, settled = sorted(outcomes, key=lambda o: o[0])[SOAK_DRAWS // 2]
    return soak_s, outcome, tuple(round(float(c), 3) for c in settled)


def _as_read(dut_c: np.ndarray, readers: list[TemperatureFormat]) -> np.ndarray:
    """Temperatures (polls × DUTs) as each DUT's temperature sensor reports them (its code, converted)."""
    read = np.empty_like(dut_c)
    for column, reader in enumerate(readers):
        read[:, column] = reader.celsius(reader.raw(dut_c[:, column]))
    return read
