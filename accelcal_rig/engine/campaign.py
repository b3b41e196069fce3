"""Execute a compiled plan: ramp, soak, then move–settle–acquire–store for every pose, then safe state.

Every wait has a deadline; any fault or signal leads through ABORTING to the safe state, is written to
the campaign file's event log, and is raised again as CampaignAborted with a one-line reason.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from itertools import groupby

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, signals_deferred
from accelcal_rig.core.waits import MOVE_POLL_S, wait_until
from accelcal_rig.engine.acquisition import acquire_together
from accelcal_rig.engine.audience import Audience, Reporter
from accelcal_rig.engine.connection import GuardedRig
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.resume import ResumePoint
from accelcal_rig.engine.safe_state import apply_safe_state, safe_setpoint_c
from accelcal_rig.engine.soak import SoakDetector
from accelcal_rig.engine.states import ACTIVE_STATES, State, StateMachine
from accelcal_rig.errors import CampaignAborted, InstrumentError, RigError, TransientInstrumentError, WaitTimeout
from accelcal_rig.instruments.interfaces import Accelerometer, DeviceIdentity, SampleBlock
from accelcal_rig.plan.compile import Plan, PlanStep, setpoint_label
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.records import DutPoseRecord, PoseRecord, SoakTrace
from accelcal_rig.store.writer import CampaignWriter

#: A move's deadline is 1.5 × its travel time at the configured speeds plus this margin.
MOVE_MARGIN_S = 30.0


#: States in which the campaign still has measuring ahead of it (the time left is estimated).

#: Runs on the stored campaign once the rig is safe; returns a one-line summary of the calibration.
FitStage = Callable[[Campaign], str]


@dataclass(frozen=True)
class CampaignSummary:
    state: str
    setpoints_c: tuple[float, ...]
    poses_done: int
    poses_total: int
    n_duts: int
    virtual_duration_s: float
    fit: str = ""                 # the fit stage's summary, or why it failed
    fit_failed: bool = False


class CampaignRunner:
    def __init__(self, procedure: Procedure, rig: RigConfig, plan: Plan, guarded: GuardedRig,
                 writer: CampaignWriter, clock: Clock, events: EventLog, fit_stage: FitStage | None = None,
                 resume: ResumePoint | None = None, audience: Audience = Audience()) -> None:
        self.procedure = procedure
        self.rig = rig
        self.plan = plan
        self.retrier = guarded.retrier
        instruments = guarded.instruments
        self.chamber, self.turntable, self.sensors = instruments.chamber, instruments.turntable, instruments.sensors
        self.truth = instruments.truth
        self.writer = writer
        self.clock = clock
        self.events = events
        self.fit_stage = fit_stage
        self.machine = StateMachine(self._record_transition)
        self.resume = resume
        self._stored_keys = resume.done_keys if resume is not None else frozenset()
        self._mounts = {s.serial: Rotation.from_euler("xyz", s.mount_euler_deg, degrees=True)
                        for s in rig.fixture.sensors}
        self._settled_dut_c = np.zeros(len(self.sensors))
        #: The table's angles as last read within this setpoint's poses (None: read before moving).
        self._table_angles_deg: np.ndarray | None = None
        self.safe_setpoint_c = safe_setpoint_c(procedure, rig)
        stored = self._stored_keys
        self.report = Reporter(audience, plan, procedure.name, clock, procedure.cooldown is not None,
                               [sum(1 for s in plan.pose_steps if s.setpoint_c == setpoint and s.key not in stored)
                                for setpoint in plan.setpoints_c], len(stored))
        #: True while the DUT temperatures move on purpose (cool-down, ramp): no band warnings then.
        self._temperature_moving = False
        #: The ramp method's software ramp once running: (clock time, setpoint °C) it started from.
        self._ramp_origin: tuple[float, float] | None = None
        self._ramp_written_s = float("-inf")

    # ----------------------------------------------------------------- top level
    def run(self) -> CampaignSummary:
        try:
            self.writer.set_state("running")
            self.events.info("plan", f"{len(self.plan.setpoints_c)} setpoints × {len(self.plan.poses)} poses = "
                                     f"{len(self.plan.pose_steps)} poses, {len(self.sensors)} DUTs, "
                                     f"{self.procedure.acquisition.samples_per_pose} samples per pose")
            run = f" (run {self.resume.run}, resuming after {self.report.poses_done} stored poses)" if self.resume else ""
            self.report.notify("start", f"campaign started{run}: {len(self.plan.pose_steps) - self.report.poses_done} poses to "
                                  f"measure" + (f", about {format_duration(self.report.remaining_s(self.machine.state) or 0.0)}"
                                                if self.report.audience.estimate else ""))
            if self.resume is not None and self.resume.unclean:
                self.events.warning("resume", "the last run ended without closing the file (its process died): "
                                              "safe state first")
                apply_safe_state(self.chamber, self.turntable, self.sensors, self.safe_setpoint_c, self.events)
            self.machine.go(State.PREFLIGHT)
            self._preflight()
            for setpoint, steps in groupby(self.plan.steps, key=lambda s: s.setpoint_c):
                self._run_setpoint(setpoint, [s for s in steps if s.key not in self._stored_keys])
            self.machine.go(State.SAFE, "campaign complete")
            safe = apply_safe_state(self.chamber, self.turntable, self.sensors, self.safe_setpoint_c, self.events)
            self.report.notify("safe", "every pose measured; rig in its safe state" if safe else
                                 "every pose measured; safe state INCOMPLETE: see the event log")
            fit, fit_failed = self._fit() if self.fit_stage is not None else ("", False)
            self.machine.go(State.DONE)
            self.writer.set_state("done", finished=True)
            self.report.notify("finish", f"campaign done; fit failed: {fit}" if fit_failed else f"campaign done; {fit}")
            return self._summary("done", fit, fit_failed)
        except BaseException as exc:  # noqa: BLE001 - every exit path goes through the safe state
            reason = one_line_reason(exc)
            self._abort(reason)
            raise CampaignAborted(reason) from exc

    def _abort(self, reason: str) -> None:
        """Safe state first, bookkeeping after: a broken file must not keep the rig unsafe.

        Signals wait until the abort is complete: a Ctrl-C now cannot cut the safe state short.
        """
        with signals_deferred():
            self._make_safe_and_record(reason)

    def _make_safe_and_record(self, reason: str) -> None:
        if self.machine.state in ACTIVE_STATES:
            self.machine.go(State.ABORTING, reason)
            self.machine.go(State.SAFE, "abort")
        self.events.error("fault", f"campaign aborted: {reason}")
        self.report.notify("fault", f"campaign aborted: {reason}")
        safe = apply_safe_state(self.chamber, self.turntable, self.sensors, self.safe_setpoint_c, self.events)
        self.report.notify("safe", f"rig in its safe state; {self.report.poses_done} of {len(self.plan.pose_steps)} poses stored"
                     if safe else "safe state INCOMPLETE: check the rig; see the event log")
        if self.machine.state is State.SAFE:
            self.machine.go(State.ABORTED)
        try:
            self.writer.set_state("aborted", reason=reason, finished=True)
        except Exception as exc:  # noqa: BLE001 - the reason still reaches the operator through the exception
            LOGGER.error("could not record the abort in the campaign file: %s", exc)

    def _fit(self) -> tuple[str, bool]:
        """The measurements are complete and the rig is safe: a fit that fails is reported, not an abort."""
        assert self.fit_stage is not None
        self.machine.go(State.FIT)
        try:
            summary = self.fit_stage(self.writer.campaign)
        except (ValueError, KeyError, OSError, np.linalg.LinAlgError, RigError) as exc:
            self.events.error("fit", f"fit failed: {exc}")
            return str(exc), True
        self.events.info("fit", summary)
        return summary, False

    def _summary(self, state: str, fit: str = "", fit_failed: bool = False) -> CampaignSummary:
        return CampaignSummary(state, self.plan.setpoints_c, self.report.poses_done, len(self.plan.pose_steps),
                               len(self.sensors), self.clock.now(), fit, fit_failed)

    def _record_transition(self, previous: State, target: State, reason: str) -> None:
        suffix = f" ({reason})" if reason else ""
        self.events.debug("transition", f"{previous} → {target}{suffix}")
        if self.report.phase_of(target) != self.report.phase_of(previous):
            self.report.publish(self.machine.state)  # within a pose the snapshot after storing it says all

    # ----------------------------------------------------------------- preflight
    def _preflight(self) -> None:
        """Check identities and configure every DUT before anything moves."""
        self.events.info("preflight", f"chamber: {self.chamber.identify()} ({self.chamber.endpoint})")
        self.events.info("preflight", f"turntable: {self.turntable.identify()} ({self.turntable.endpoint})")
        acquisition = self.procedure.acquisition
        for sensor in self.sensors:
            identity = self.retrier.call(partial(_checked_identity, sensor))
            sensor.reset()
            sensor.standby()
            sensor.configure(acquisition.range_g, acquisition.odr_hz)
            sensor.start_measurement()
            self.events.info("preflight", f"sensor {sensor.serial}: {sensor.part.label} rev {identity.revid}, "
                                          f"±{acquisition.range_g} g, {acquisition.odr_hz:g} Hz")

    # ----------------------------------------------------------------- one setpoint
    def _run_setpoint(self, setpoint_c: float, steps: list[PlanStep]) -> None:
        """Ramp, soak and measure the poses in `steps` (those not stored yet); nothing if none are left."""
        label = setpoint_label(setpoint_c)
        if not any(s.kind == "pose" for s in steps):
            self.events.info("setpoint", f"{label}: every pose already stored")
            return
        self.report.begin_setpoint(setpoint_c)
        self.writer.check_space(sum(self.report.poses_left[self.report.setpoint_index:]))
        self.machine.go(State.RAMP, label)
        pose_steps = [s for s in steps if s.kind == "pose"]
        if self._ramp_origin is not None and setpoint_c != self.plan.setpoints_c[-1]:
            self._follow_ramp_to(self._cycle_start_c(setpoint_c))
        elif self._ramp_origin is not None:
            # The end of the ramp: hold the last setpoint until the DUTs, lagging the air, have caught up, so
            # the calibrated range reaches it.
            self._follow_ramp_to(setpoint_c)
            self._temperature_moving = False
            self.machine.go(State.SOAK, label)
            if not self._soak(setpoint_c, label, self.clock.now(), len(pose_steps)):
                return
        else:
            t_reached = self._ramp(setpoint_c)
            self.machine.go(State.SOAK, label)
            if not self._soak(setpoint_c, label, t_reached, len(pose_steps)):
                return
            self._table_angles_deg = None  # hours of soak: ask the table where it is
            if self.procedure.method == "ramp":
                self._start_software_ramp(setpoint_c)
        if self.procedure.cooldown is not None:
            self._cool_down(pose_steps)
        else:
            for step in pose_steps:
                self._advance_software_ramp()
                self._measure_pose(step)
        total = len(self.plan.pose_steps)
        self.events.info("setpoint", f"{label}: {len(pose_steps)} poses stored ({self.report.poses_done}/{total} in all)")

    # ----------------------------------------------------------------- the ramp method
    def _start_software_ramp(self, setpoint_c: float) -> None:
        """From the soak at `setpoint_c` on, move the chamber setpoint at the procedure's rate towards the
        last setpoint, where it soaks again; the poses in between follow the ramp."""
        assert self.procedure.ramp is not None
        self._ramp_origin = (self.clock.now(), setpoint_c)
        self._temperature_moving = True
        last = self.plan.setpoints_c[-1]
        self.events.info("ramp", f"ramp method: chamber setpoint moving {setpoint_c:g} → {last:g} °C at "
                                 f"{self.procedure.ramp.rate_c_per_min:g} °C/min, poses taken as it goes")

    def _ramp_setpoint_c(self, t_s: float) -> float:
        """Where the software ramp is at clock time `t_s`, stopping at the last setpoint."""
        assert self._ramp_origin is not None and self.procedure.ramp is not None
        t0, start_c = self._ramp_origin
        last = self.plan.setpoints_c[-1]
        travelled = self.procedure.ramp.rate_c_per_min / 60.0 * (t_s - t0)
        return float(min(start_c + travelled, last) if last > start_c else max(start_c - travelled, last))

    def _cycle_start_c(self, setpoint_c: float) -> float:
        """A setpoint's poses begin half-way from the previous setpoint."""
        index = self.plan.setpoints_c.index(setpoint_c)
        return 0.5 * (self.plan.setpoints_c[index - 1] + setpoint_c) if index else setpoint_c

    def _advance_software_ramp(self) -> None:
        """Write the ramp's current setpoint, at most every `ramp.update_s`."""
        if self._ramp_origin is None:
            return
        assert self.procedure.ramp is not None
        now = self.clock.now()
        if now - self._ramp_written_s >= self.procedure.ramp.update_s:
            self.chamber.write_setpoint_c(round(self._ramp_setpoint_c(now), 3))
            self._ramp_written_s = now

    def _follow_ramp_to(self, target_c: float) -> None:
        """Keep the software ramp moving until it reaches `target_c` (at once if it already has)."""
        assert self._ramp_origin is not None and self.procedure.ramp is not None
        t0, start_c = self._ramp_origin
        arrival_s = t0 + abs(target_c - start_c) / (self.procedure.ramp.rate_c_per_min / 60.0)
        while self.clock.now() < arrival_s:
            self._advance_software_ramp()
            self._chamber_temperature_c()  # the alarm, and what the progress display shows
            self.report.publish(self.machine.state)
            self.clock.sleep(min(self.procedure.ramp.update_s, arrival_s - self.clock.now()))
        self._advance_software_ramp()

    def _cool_down(self, steps: list[PlanStep]) -> None:
        """Hold the pose, record once at the setpoint, let the chamber go, record on schedule while the DUTs
        cool. A resumed cool-down records its missing blocks on a fresh schedule after a fresh soak."""
        cooldown = self.procedure.cooldown
        assert cooldown is not None
        released_s = self.clock.now()
        self._temperature_moving = True
        for index, step in enumerate(steps):
            if index:  # every record_every_s from the moment the chamber was let go
                self.machine.go(State.COOL, step.key)
                self.clock.sleep(max(released_s + index * cooldown.record_every_s - self.clock.now(), 0.0))
            self._measure_pose(step)
            if index == 0:
                released_s = self.clock.now()
                if cooldown.chamber == "power-off":
                    self.chamber.set_power(False)
                    self.events.info("cooldown", "chamber switched off: the DUTs cool freely; recording every "
                                                 f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
                else:
                    self.chamber.write_setpoint_c(cooldown.ambient_c)
                    self.events.info("cooldown", f"chamber set to ambient {cooldown.ambient_c:g} °C; recording every "
                                                 f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
        self._temperature_moving = False

    def _ramp(self, setpoint_c: float) -> float:
        soak = self.procedure.soak
        if self.procedure.cooldown is not None and self.procedure.cooldown.chamber == "power-off":
            self.chamber.set_power(True)  # a cool-down switches it off; a resumed one needs it on again
        start_c = self._chamber_temperature_c()
        self.chamber.write_setpoint_c(setpoint_c)
        ramp_s = abs(setpoint_c - start_c) / (self.rig.chamber.ramp_rate_c_per_min / 60.0)
        timeout_s = soak.ramp_timeout_factor * ramp_s + soak.ramp_timeout_margin_min * 60.0
        self.events.info("ramp", f"ramp {start_c:.1f} → {setpoint_c:g} °C (deadline {format_duration(timeout_s)})")
        def reached() -> bool:
            within = abs(self._chamber_temperature_c() - setpoint_c) <= soak.chamber_tolerance_c
            self.report.publish(self.machine.state)
            return within

        t_reached = wait_until(
            self.clock, reached,
            timeout_s=timeout_s, poll_s=soak.poll_s,
            what=f"chamber ({self.chamber.endpoint}) reaching {setpoint_c:g} °C",
        )
        return t_reached

    def _soak(self, setpoint_c: float, label: str, t_reached: float, n_poses: int) -> bool:
        """Wait for thermal stability; False when the setpoint is to be skipped (`soak.on_timeout: skip`)."""
        criterion = self.procedure.soak
        detector = SoakDetector(criterion, setpoint_c, t_reached)

        def poll() -> bool:
            dut_c = np.array([s.read_temperature_c() for s in self.sensors])
            detector.add(self.clock.now(), self._chamber_temperature_c(), dut_c)
            self.report.dut_c = tuple(dut_c.tolist())
            self.report.publish(self.machine.state)
            return detector.is_stable()

        outcome, t_stable = "fault", float("nan")  # what the file says if anything but the deadline stops it
        try:
            t_stable = wait_until(self.clock, poll, timeout_s=criterion.timeout_min * 60.0, poll_s=criterion.poll_s,
                                  what=f"{label}: DUT temperatures stable within {criterion.band_c:g} °C")
            outcome = "stable"
        except WaitTimeout as exc:
            outcome = "timeout"
            if criterion.on_timeout == "abort":
                raise
            timed_out = exc
        finally:
            t, chamber, dut = detector.trace()
            self._settled_dut_c = detector.settled_dut_c() if len(t) else np.full(len(self.sensors), np.nan)
            self.writer.write_soak(SoakTrace(label, setpoint_c, outcome, t, chamber, dut, t_reached, t_stable,
                                             self._settled_dut_c, tuple(s.serial for s in self.sensors)))
        if outcome == "timeout":
            if criterion.on_timeout == "skip":
                self.events.warning("soak", f"{timed_out}; setpoint skipped, its {n_poses} poses not measured "
                                            "(soak.on_timeout: skip)")
                self.report.notify("soak", f"{timed_out}; setpoint skipped (soak.on_timeout: skip)")
                self.report.poses_left[self.report.setpoint_index] = 0
                return False
            self.events.warning("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            self.report.notify("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            return True
        spans = detector.dut_spans_c()
        message = (f"{label}: stable after {format_duration(t_stable - t_reached)} at DUT "
                   f"{np.round(self._settled_dut_c, 2).tolist()} °C (spans ≤ {spans.max():.2f} °C)")
        self.events.info("soak", message)
        self.report.notify("soak", message)
        return True

    def _chamber_temperature_c(self) -> float:
        """Chamber air temperature; an active controller alarm is a fault, never a reading to wait out."""
        if self.chamber.alarm_active():
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): controller alarm active")
        self.report.chamber_c = self.chamber.read_temperature_c()
        return self.report.chamber_c

    # ----------------------------------------------------------------- one pose
    def _measure_pose(self, step: PlanStep) -> None:
        assert step.pose is not None
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
        chamber_after = self._chamber_temperature_c()
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
        in_band = bool(np.all(np.abs(np.array(block.temperature_c) - self._settled_dut_c[index]) <= band))
        if not in_band and not self._temperature_moving:
            before, after = block.temperature_c
            self.events.warning("pose", f"sensor {sensor.serial}: temperature {before:.2f}/{after:.2f} °C left the "
                                        f"±{band:g} °C band around {self._settled_dut_c[index]:.2f} °C")
        return DutPoseRecord(
            serial=sensor.serial, raw_codes=codes, mean_g=mean_g, stderr_g=stderr_g,
            temperature_c=block.temperature_c,
            gravity_reference_g=self._mounts[sensor.serial].inv().apply(gravity_fixture),
            temperature_in_band=in_band,
            truth=self.truth.block_truth(sensor.serial, block) if self.truth is not None else None,
        )


def _angle_difference(a_deg: np.ndarray, b_deg: np.ndarray) -> np.ndarray:
    """a − b wrapped into [−180, 180)."""
    return (np.asarray(a_deg) - np.asarray(b_deg) + 180.0) % 360.0 - 180.0


def _checked_identity(sensor: Accelerometer) -> DeviceIdentity:
    """The sensor's identity registers; anything but its part's may be a glitch on the line (retried),
    and is a fault when it persists."""
    identity = sensor.identify()
    wrong = sensor.part.wrong_identity((identity.devid_ad, identity.devid_mst, identity.partid))
    if wrong:
        raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): {wrong}")
    return identity


def one_line_reason(exc: BaseException) -> str:
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted by operator (Ctrl-C)"
    if isinstance(exc, TerminationRequested):
        return "terminated by signal (SIGTERM)"
    if isinstance(exc, RigError):
        return str(exc).splitlines()[0]
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
