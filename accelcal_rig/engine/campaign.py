"""The runner: a campaign's lifecycle — preflight, the plan's steps in order, the safe state, the fit —
while its audience is told (engine/audience.py).

The runner does not know what a step does: it hands each to the handler for its type (thermal steps in
engine/thermal_steps.py, poses in engine/pose_steps.py, a cool-down's records in engine/cooldown_steps.py,
the purge and the dew point in engine/frost_steps.py).
It knows where a resumed run begins (the steps not stored yet, a setpoint's restart entry) and that a
skipped soak skips the rest of its setpoint.

Every wait has a deadline; any fault or signal leads through ABORTING to the safe state, is written to
the campaign file's event log, and is raised again as CampaignAborted with a one-line reason.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, signals_deferred
from accelcal_rig.engine.audience import Audience, Reporter
from accelcal_rig.engine.connection import GuardedRig
from accelcal_rig.engine.cooldown_steps import CooldownSteps
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.frost_steps import FrostSteps
from accelcal_rig.engine.pose_steps import PoseSteps
from accelcal_rig.engine.resume import ResumePoint
from accelcal_rig.engine.safe_state import apply_safe_state, safe_setpoint_c
from accelcal_rig.engine.states import ACTIVE_STATES, State, StateMachine
from accelcal_rig.engine.thermal_steps import SetpointSkipped, ThermalSteps
from accelcal_rig.errors import CampaignAborted, InstrumentError, RigError, TransientInstrumentError
from accelcal_rig.instruments.interfaces import Accelerometer, DeviceIdentity
from accelcal_rig.plan.compile import Plan, setpoint_label
from accelcal_rig.plan.steps import (
    AdvanceRamp,
    AwaitDewPointMargin,
    CooldownRecord,
    Measurement,
    MeasurePose,
    Ramp,
    RampSegment,
    SetPurge,
    Soak,
    StartSoftwareRamp,
    Step,
    VerifyPose,
)
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.writer import CampaignWriter


@dataclass(frozen=True)
class FitOutcome:
    """What the fit stage says: a one-line summary, each DUT's verdict and reasons, the fit's warnings."""

    summary: str
    verdicts: dict[str, tuple[str, tuple[str, ...]]] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()


#: Runs on the stored campaign once the rig is safe.
FitStage = Callable[[Campaign], FitOutcome]


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
    verdicts: dict[str, tuple[str, tuple[str, ...]]] = field(default_factory=dict)  # serial → (PASS|FAIL, reasons)
    fit_warnings: tuple[str, ...] = ()

    @property
    def rejected(self) -> list[str]:
        """The DUTs whose calibration failed its acceptance limits."""
        return [serial for serial, (verdict, _) in self.verdicts.items() if verdict == "FAIL"]


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
        self._fit_error = ""
        self.machine = StateMachine(self._record_transition)
        self.resume = resume
        self._stored_keys = resume.done_keys if resume is not None else frozenset()
        self.safe_setpoint_c = safe_setpoint_c(procedure, rig)
        stored = self._stored_keys
        self.report = Reporter(audience, plan, procedure.name, clock, procedure.cooldown is not None,
                               [sum(1 for s in plan.pose_steps if s.setpoint_c == setpoint and s.key not in stored)
                                for setpoint in plan.setpoints_c], len(stored))
        self.thermal = ThermalSteps(procedure, rig, plan, self.chamber, self.sensors, clock, events, writer,
                                    self.machine, self.report)
        self.poses = PoseSteps(procedure, rig, guarded, clock, events, writer, self.machine, self.report, self.thermal)
        cooldown = CooldownSteps(procedure, self.chamber, clock, events, self.machine, self.thermal, self.poses)
        self.frost = FrostSteps(procedure, rig, self.thermal, self.sensors, clock, events, self.report)
        #: What each type of step is done by.
        self.handlers: Mapping[type, Callable[[Any], None]] = {
            Ramp: self.thermal.ramp, Soak: self.thermal.soak, StartSoftwareRamp: self.thermal.start_software_ramp,
            RampSegment: self.thermal.follow_software_ramp, AdvanceRamp: self.thermal.advance_software_ramp,
            MeasurePose: self.poses.measure, VerifyPose: self.poses.measure, CooldownRecord: cooldown.record,
            SetPurge: self.frost.set_purge, AwaitDewPointMargin: self.frost.await_dew_point_margin,
        }

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
            self._run_stages()
            self.machine.go(State.SAFE, "campaign complete")
            safe = apply_safe_state(self.chamber, self.turntable, self.sensors, self.safe_setpoint_c, self.events)
            self.frost.note_purge_left_on()
            self.report.notify("safe", "every pose measured; rig in its safe state" if safe else
                                 "every pose measured; safe state INCOMPLETE: see the event log")
            fit = self._fit() if self.fit_stage is not None else FitOutcome("")
            failed = fit is None
            outcome = fit or FitOutcome(self._fit_error)
            self.machine.go(State.DONE)
            self.writer.set_state("done", finished=True)
            self.report.notify("finish", f"campaign done; fit failed: {outcome.summary}" if failed
                               else f"campaign done; {outcome.summary}")
            return replace(self._summary("done", outcome.summary, failed), verdicts=outcome.verdicts,
                           fit_warnings=outcome.warnings)
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
        self.frost.note_purge_left_on()
        self.report.notify("safe", f"rig in its safe state; {self.report.poses_done} of {len(self.plan.pose_steps)} poses stored"
                     if safe else "safe state INCOMPLETE: check the rig; see the event log")
        if self.machine.state is State.SAFE:
            self.machine.go(State.ABORTED)
        try:
            self.writer.set_state("aborted", reason=reason, finished=True)
        except Exception as exc:  # noqa: BLE001 - the reason still reaches the operator through the exception
            LOGGER.error("could not record the abort in the campaign file: %s", exc)

    def _fit(self) -> FitOutcome | None:
        """The measurements are complete and the rig is safe: a fit that fails is reported (None, the reason
        in `_fit_error`), not an abort. The fit's warnings and every DUT's verdict go to the event log."""
        assert self.fit_stage is not None
        self.machine.go(State.FIT)
        try:
            outcome = self.fit_stage(self.writer.campaign)
        except (ValueError, KeyError, OSError, np.linalg.LinAlgError, RigError) as exc:
            self.events.error("fit", f"fit failed: {exc}")
            self._fit_error = str(exc)
            return None
        self.events.info("fit", outcome.summary)
        for warning in outcome.warnings:
            self.events.warning("fit", warning)
        for serial, (verdict, reasons) in outcome.verdicts.items():
            log = self.events.info if verdict == "PASS" else self.events.warning
            log("verdict", f"{serial}: {verdict}: {'; '.join(reasons)}")
        return outcome

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
        self._check_controller_limits()
        self.frost.preflight(self.plan)
        self.events.info("preflight", f"turntable: {self.turntable.identify()} ({self.turntable.endpoint})")
        acquisition = self.procedure.acquisition
        for sensor in self.sensors:
            identity = self.retrier.call(partial(_checked_identity, sensor))
            sensor.reset()
            sensor.standby()
            sensor.configure(acquisition.range_g, acquisition.odr_hz)
            sensor.start_measurement()
            self.events.info("preflight", f"sensor {sensor.serial}: {sensor.part.label} rev {identity.revid} "
                                          f"(DEVID_AD 0x{identity.devid_ad:02X}, DEVID_MST 0x{identity.devid_mst:02X}, "
                                          f"PARTID 0x{identity.partid:02X}), ±{acquisition.range_g} g, "
                                          f"{acquisition.odr_hz:g} Hz")

    def _check_controller_limits(self) -> None:
        """Every setpoint the campaign will write within what the controller itself accepts, or a fault now
        (a controller clamps silently: the campaign would wait for a temperature it never sets)."""
        limits = self.chamber.controller_limits_c()
        if limits is None:
            return
        low, high = limits
        self.events.info("preflight", f"chamber: the controller's own set point limits {low:g}…{high:g} °C")
        wanted = [*self.plan.setpoints_c, self.safe_setpoint_c]
        if self.procedure.cooldown is not None and self.procedure.cooldown.chamber == "ambient":
            wanted.append(self.procedure.cooldown.ambient_c)
        beyond = [t for t in wanted if not low <= t <= high]
        if beyond:
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): {beyond[0]:g} °C is beyond the controller's own "
                                  f"set point limits {low:g}…{high:g} °C: change them on the controller, or the "
                                  "procedure")

    # ----------------------------------------------------------------- the plan
    def _run_stages(self) -> None:
        """Each setpoint's steps not stored yet. A run begins at its first setpoint with something left to
        measure through that setpoint's restart entry, and so does the setpoint after a skipped soak or after
        one whose poses were all stored (the rig did not go there)."""
        restarting = True
        for stage in self.plan.stages:
            label = setpoint_label(stage.setpoint_c)
            body = [s for s in stage.body if not (isinstance(s, Measurement) and s.key in self._stored_keys)]
            if not any(isinstance(s, Measurement) for s in body):
                self.events.info("setpoint", f"{label}: every pose already stored")
                restarting = True  # the rig did not go there: the next setpoint assumes nothing of it
                continue
            self.report.begin_setpoint(stage.setpoint_c)
            self.writer.check_space(sum(self.report.poses_left[self.report.setpoint_index:]))
            try:
                for step in (*(stage.restart_entry if restarting else stage.entry), *body):
                    self._execute(step)
            except SetpointSkipped:
                restarting = True
                continue
            restarting = False
            stored = sum(isinstance(s, Measurement) for s in body)
            self.events.info("setpoint", f"{label}: {stored} poses stored "
                                         f"({self.report.poses_done}/{len(self.plan.pose_steps)} in all)")

    def _execute(self, step: Step) -> None:
        handler = self.handlers.get(type(step))
        if handler is None:
            raise TypeError(f"no handler for a plan step of type {type(step).__name__}")
        handler(step)


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
