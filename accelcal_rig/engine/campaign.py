"""The runner: a campaign's lifecycle — preflight, the plan's steps in order, the safe state, the fit —
while its audience is told (engine/audience.py).

The runner does not know what a step does: it hands each to the handler of its kind (engine/step_table.py:
thermal steps in engine/thermal_steps.py, poses in engine/pose_steps.py, a cool-down's records in
engine/cooldown_steps.py, the purge and the dew point in engine/frost_steps.py), with the run's context.
It knows where a resumed run begins (the steps not stored yet, a setpoint's restart entry) and that a
skipped soak skips the rest of its setpoint.

Every wait has a deadline; any fault or signal leads through ABORTING to the safe state, is written to
the campaign file's event log, and is raised again as CampaignAborted with a one-line reason. The safe
state is applied in one place on every way out (`_reach_safe_state`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.core.signals import TerminationRequested, signals_deferred
from accelcal_rig.engine.audience import Audience, Reporter
from accelcal_rig.engine.connection import ConnectedRig
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.frost_steps import frost_preflight, note_purge_left_on
from accelcal_rig.engine.rate_steps import bring_rate_axes_to_rest
from accelcal_rig.engine.resume import ResumePoint
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.safe_state import apply_safe_state, safe_setpoint_c
from accelcal_rig.engine.states import ACTIVE_STATES, TRANSITION_KIND, State, StateMachine, transition_text
from accelcal_rig.engine.step_table import handler_for
from accelcal_rig.engine.thermal_steps import SetpointSkipped
from accelcal_rig.errors import CampaignAborted, InstrumentError, RigError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import controller_limits
from accelcal_rig.instruments.interfaces import DeviceIdentity, Sensor
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.plan.compile import Plan, setpoint_label
from accelcal_rig.plan.composition import plan_composition
from accelcal_rig.plan.steps import Measurement
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
    """One run of a campaign, from opening its file to its end: the file opened by `open_writer` (a failure
    there is raised as it is: nothing was touched), then the preflight and the plan's steps, then the safe
    state — reached in one place, `_reach_safe_state`, whatever ended the measuring — and the fit."""

    def __init__(self, procedure: Procedure, rig: RigConfig, plan: Plan, connected: ConnectedRig,
                 open_writer: Callable[[], CampaignWriter], fit_stage: FitStage | None = None,
                 resume: ResumePoint | None = None, audience: Audience = Audience()) -> None:
        self.procedure, self.rig, self.plan = procedure, rig, plan
        self.connected, self.clock = connected, connected.clock
        self._open_writer = open_writer
        self.fit_stage = fit_stage
        self._fit_error = ""
        self.machine = StateMachine(self._record_transition)
        self.resume = resume
        self._stored_keys = resume.done_keys if resume is not None else frozenset()
        self.safe_setpoint_c = safe_setpoint_c(procedure, rig)
        stored = self._stored_keys
        self.report = Reporter(audience, plan, procedure.name, self.clock, procedure.cooldown is not None,
                               [sum(1 for s in plan.pose_steps if s.setpoint_c == setpoint and s.key not in stored)
                                for setpoint in plan.setpoints_c], len(stored))
        #: The campaign's file once open (None: it did not open), its event log, and the run's context once
        #: the instruments are wrapped for it.
        self.writer: CampaignWriter | None = None
        self.events: EventLog | None = None
        self.context: RunContext | None = None

    # ----------------------------------------------------------------- top level
    def run(self) -> CampaignSummary:
        """Open the file, measure, reach the safe state, fit. Raises CampaignAborted after the safe state."""
        failure: BaseException | None = None
        try:
            with signals_deferred():  # a stop while the file opens is raised once it is open, and recorded
                self.writer = self._open_writer()
                self.events = EventLog(self.clock, self.writer)
            self._measure()
        except BaseException as exc:  # noqa: BLE001 - every exit path goes through the safe state
            if self.events is None:
                raise  # the file did not open: nothing was touched, nothing to record
            failure = exc
        try:
            with signals_deferred():  # a Ctrl-C now cannot cut the safe state short
                self._reach_safe_state(failure)
        except BaseException as exc:  # noqa: BLE001 - a stop during the safe state: the rig is safe, the run ends
            failure = failure or exc
        if failure is None:
            try:
                return self._finish()
            except BaseException as exc:  # noqa: BLE001 - the fit stage stopped: the rig is already safe
                failure = exc
                with signals_deferred():
                    self._go_safe(one_line_reason(exc))
        reason = one_line_reason(failure)
        with signals_deferred():
            self._record_abort(reason)
        raise CampaignAborted(reason) from failure

    def _measure(self) -> None:
        """The run's context, the preflight and the plan's steps not stored yet."""
        assert self.writer is not None and self.events is not None
        events = self.events
        guarded = self.connected.guarded(events)
        self.context = RunContext(self.procedure, self.rig, self.plan, guarded.instruments, guarded.retrier,
                                  self.clock, events, self.writer, self.machine, self.report)
        self.writer.set_state("running")
        events.info("plan", f"{len(self.plan.setpoints_c)} setpoints; {plan_composition(self.plan)}; "
                            f"{len(self.context.sensors)} DUTs, {self.procedure.acquisition.samples_per_pose} samples "
                            "per pose")
        run = f" (run {self.resume.run}, resuming after {self.report.poses_done} stored poses)" if self.resume else ""
        estimate = (f", about {format_duration(self.report.remaining_s(self.machine.state) or 0.0)}"
                    if self.report.audience.estimate else "")
        self.report.notify("start", f"campaign started{run}: {len(self.plan.pose_steps) - self.report.poses_done} "
                                    f"poses to measure{estimate}")
        if self.resume is not None and self.resume.unclean:
            events.warning("resume", "the last run ended without closing the file (its process died): "
                                     "safe state first")
            self._apply_safe_state()
        self.machine.go(State.PREFLIGHT)
        self._preflight()
        self._run_stages()

    def _reach_safe_state(self, failure: BaseException | None) -> None:
        """Every way the measuring ends leads here: the state machine to SAFE, the rig safe, the audience told."""
        assert self.events is not None
        try:
            if failure is None:
                self.machine.go(State.SAFE, "campaign complete")
            else:
                self._go_safe(one_line_reason(failure))
        finally:  # the bookkeeping before it may fail (a full disk, a bug): never the rig's safe state
            safe = self._apply_safe_state()
        if self.context is not None:
            note_purge_left_on(self.context)
        total = len(self.plan.pose_steps)
        if failure is None:
            self.report.notify("safe", "every pose measured; rig in its safe state" if safe else
                               "every pose measured; safe state INCOMPLETE: see the event log")
        else:
            self.report.notify("safe", f"rig in its safe state; {self.report.poses_done} of {total} poses stored"
                               if safe else "safe state INCOMPLETE: check the rig; see the event log")

    def _go_safe(self, reason: str) -> None:
        """A fault or stop: through ABORTING to SAFE, and the reason in the event log and to the notifier."""
        assert self.events is not None
        started = self.machine.state is not State.IDLE
        if self.machine.state in ACTIVE_STATES:
            self.machine.go(State.ABORTING, reason)
            self.machine.go(State.SAFE, "abort")
        self.events.error("fault", f"campaign aborted: {reason}" if started
                          else f"campaign aborted before its first step: {reason}")
        self.report.notify("fault", f"campaign aborted: {reason}")

    def _apply_safe_state(self) -> bool:
        """The rig's safe state, through the guarded instruments once the run has them, else as connected."""
        assert self.events is not None
        instruments = self.context.instruments if self.context is not None else self.connected.instruments
        return apply_safe_state(instruments.chamber, instruments.turntable, instruments.sensors,
                                self.safe_setpoint_c, self.events)

    def _record_abort(self, reason: str) -> None:
        """The rig is safe: the file says the campaign ended and why."""
        if self.machine.state is State.SAFE:
            self.machine.go(State.ABORTED)
        try:
            assert self.writer is not None
            self.writer.set_state("aborted", reason=reason, finished=True)
        except Exception as exc:  # noqa: BLE001 - the reason still reaches the operator through the exception
            LOGGER.error("could not record the abort in the campaign file: %s", exc)

    def _finish(self) -> CampaignSummary:
        """The rig is safe and every pose measured: the fit, then done."""
        assert self.writer is not None
        fit = self._fit() if self.fit_stage is not None else FitOutcome("")
        failed = fit is None
        outcome = fit or FitOutcome(self._fit_error)
        self.machine.go(State.DONE)
        self.writer.set_state("done", finished=True)
        self.report.notify("finish", f"campaign done; fit failed: {outcome.summary}" if failed
                           else f"campaign done; {outcome.summary}")
        return replace(self._summary("done", outcome.summary, failed), verdicts=outcome.verdicts,
                       fit_warnings=outcome.warnings)

    def _fit(self) -> FitOutcome | None:
        """The measurements are complete and the rig is safe: a fit that fails is reported (None, the reason
        in `_fit_error`), not an abort. The fit's warnings and every DUT's verdict go to the event log."""
        assert self.fit_stage is not None and self.writer is not None and self.events is not None
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
            log = self.events.warning if verdict == "FAIL" else self.events.info
            log("verdict", f"{serial}: {verdict}: {'; '.join(reasons)}")
        return outcome

    def _summary(self, state: str, fit: str = "", fit_failed: bool = False) -> CampaignSummary:
        n_duts = len(self.connected.instruments.sensors)
        return CampaignSummary(state, self.plan.setpoints_c, self.report.poses_done, len(self.plan.pose_steps),
                               n_duts, self.clock.now(), fit, fit_failed)

    def _record_transition(self, previous: State, target: State, reason: str) -> None:
        if self.events is not None:
            self.events.debug(TRANSITION_KIND, transition_text(previous, target, reason))
        if self.report.phase_of(target) != self.report.phase_of(previous):
            self.report.publish(self.machine.state)  # within a pose the snapshot after storing it says all

    # ----------------------------------------------------------------- preflight
    def _preflight(self) -> None:
        """Check identities and configure every DUT before anything moves."""
        run = self.context
        assert run is not None
        chamber, events = run.chamber, run.events
        events.info("preflight", f"chamber: {chamber.identify()} ({chamber.endpoint})")
        self._check_controller_limits(run)
        frost_preflight(run)
        events.info("preflight", f"turntable: {run.turntable.identify()} ({run.turntable.endpoint})")
        bring_rate_axes_to_rest(run)
        acquisition = self.procedure.acquisition
        for sensor in run.sensors:
            identity = run.retrier.call(partial(_checked_identity, sensor))
            odr_hz = odr_hz_of(sensor.part, acquisition.odr_hz)
            sensor.reset()
            sensor.standby()
            sensor.configure(acquisition.ranges, odr_hz)
            sensor.start_measurement()
            asked = "" if odr_hz == acquisition.odr_hz else f" (its next rate above the {acquisition.odr_hz:g} Hz asked)"
            events.info("preflight", f"sensor {sensor.serial}: {identity.describe(sensor.part.label)} "
                                     f"({sensor.part.describe_identity(identity.registers)}), "
                                     f"{sensor.part.describe_ranges(acquisition.ranges)}, {odr_hz:g} Hz{asked}")
        run.sensor_ranges = dict(acquisition.ranges)

    def _check_controller_limits(self, run: RunContext) -> None:
        """Every setpoint the campaign will write within what the controller itself accepts, or a fault now
        (a controller clamps silently: the campaign would wait for a temperature it never sets)."""
        limits = controller_limits(run.chamber)
        if limits is None:
            return
        low, high = limits
        run.events.info("preflight", f"chamber: the controller's own set point limits {low:g}…{high:g} °C")
        wanted = [*self.plan.setpoints_c, self.safe_setpoint_c]
        if self.procedure.cooldown is not None and self.procedure.cooldown.chamber == "ambient":
            wanted.append(self.procedure.cooldown.ambient_c)
        beyond = [t for t in wanted if not low <= t <= high]
        if beyond:
            raise InstrumentError(f"chamber ({run.chamber.endpoint}): {beyond[0]:g} °C is beyond the controller's "
                                  f"own set point limits {low:g}…{high:g} °C: change them on the controller, or "
                                  "the procedure")

    # ----------------------------------------------------------------- the plan
    def _run_stages(self) -> None:
        """Each setpoint's steps not stored yet. A run begins at its first setpoint with something left to
        measure through that setpoint's restart entry, and so does the setpoint after a skipped soak or after
        one whose poses were all stored (the rig did not go there)."""
        run = self.context
        assert run is not None
        restarting = True
        for stage in self.plan.stages:
            label = setpoint_label(stage.setpoint_c)
            body = [s for s in stage.body if not (isinstance(s, Measurement) and s.key in self._stored_keys)]
            if not any(isinstance(s, Measurement) for s in body):
                run.events.info("setpoint", f"{label}: every pose already stored")
                restarting = True  # the rig did not go there: the next setpoint assumes nothing of it
                continue
            self.report.begin_setpoint(stage.setpoint_c)
            run.writer.check_space(sum(self.report.poses_left[self.report.setpoint_index:]))
            try:
                for step in (*(stage.restart_entry if restarting else stage.entry), *body):
                    handler_for(step).run(step, run)
            except SetpointSkipped:
                restarting = True
                continue
            restarting = False
            stored = sum(isinstance(s, Measurement) for s in body)
            run.events.info("setpoint", f"{label}: {stored} poses stored "
                                        f"({self.report.poses_done}/{len(self.plan.pose_steps)} in all)")


def _checked_identity(sensor: Sensor) -> DeviceIdentity:
    """The sensor's identity registers; anything but its part's may be a glitch on the line (retried),
    and is a fault when it persists."""
    identity = sensor.identify()
    wrong = sensor.part.wrong_identity(identity.registers)
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
