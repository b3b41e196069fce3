"""The chamber's steps of a plan: ramping to a setpoint, soaking until the DUTs are stable, the ramp method's
software ramp — and what they leave for the poses (the settled DUT temperatures, whether the temperatures
move on purpose)."""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.procedure import Procedure, SoakCriterion
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.waits import wait_until
from accelcal_rig.engine.audience import Reporter
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.soak import SoakDetector
from accelcal_rig.engine.states import State, StateMachine
from accelcal_rig.errors import InstrumentError, WaitTimeout
from accelcal_rig.instruments.interfaces import Accelerometer, Chamber
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.plan.compile import Plan, setpoint_label
from accelcal_rig.plan.steps import AdvanceRamp, Ramp, RampSegment, Soak, StartSoftwareRamp
from accelcal_rig.store.records import SoakTrace
from accelcal_rig.store.writer import CampaignWriter


class SetpointSkipped(Exception):
    """A soak ran out of time and the procedure says to skip its setpoint (`soak.on_timeout: skip`)."""


class ThermalSteps:
    def __init__(self, procedure: Procedure, rig: RigConfig, plan: Plan, chamber: Chamber,
                 sensors: list[Accelerometer], clock: Clock, events: EventLog, writer: CampaignWriter,
                 machine: StateMachine, report: Reporter) -> None:
        self.procedure, self.rig, self.plan = procedure, rig, plan
        self.chamber, self.sensors = chamber, sensors
        self.clock, self.events, self.writer, self.machine, self.report = clock, events, writer, machine, report
        #: Each DUT's temperature when its last soak settled: the band its poses are judged against.
        self.settled_dut_c = np.zeros(len(sensors))
        #: True while the DUT temperatures move on purpose (cool-down, ramp): no band warnings then.
        self.temperature_moving = False
        #: The ramp method's software ramp once running: (clock time, setpoint °C) it started from.
        self._ramp_origin: tuple[float, float] | None = None
        self._ramp_toward_c = 0.0
        self._ramp_written_s = float("-inf")
        #: When the chamber air (or the software ramp) last reached its setpoint: where a soak's deadline starts.
        self._reached_s = 0.0

    def start_software_ramp(self, step: StartSoftwareRamp) -> None:
        """From the step's setpoint on, move the chamber setpoint at the procedure's rate towards the step's
        target; the poses in between follow the ramp."""
        assert self.procedure.ramp is not None
        self._ramp_origin = (self.clock.now(), step.setpoint_c)
        self._ramp_toward_c = step.toward_c
        self._ramp_written_s = float("-inf")
        self.temperature_moving = True
        self.events.info("ramp", f"ramp method: chamber setpoint moving {step.setpoint_c:g} → {step.toward_c:g} °C "
                                 f"at {self.procedure.ramp.rate_c_per_min:g} °C/min, poses taken as it goes")

    def _ramp_setpoint_c(self, t_s: float) -> float:
        """Where the software ramp is at clock time `t_s`, stopping at the last setpoint."""
        assert self._ramp_origin is not None and self.procedure.ramp is not None
        t0, start_c = self._ramp_origin
        last = self._ramp_toward_c
        travelled = self.procedure.ramp.rate_c_per_min / 60.0 * (t_s - t0)
        return float(min(start_c + travelled, last) if last > start_c else max(start_c - travelled, last))

    def advance_software_ramp(self, step: AdvanceRamp) -> None:
        """Between poses on the ramp: write its current setpoint."""
        self.write_ramp_setpoint()

    def write_ramp_setpoint(self, arrived: bool = False) -> None:
        """Write the software ramp's current setpoint, at most every `ramp.update_s` (`arrived`: now, where
        a segment ends: the chamber must be left at the ramp's end, not an update short of it)."""
        if self._ramp_origin is None:
            return
        assert self.procedure.ramp is not None
        now = self.clock.now()
        if arrived or now - self._ramp_written_s >= self.procedure.ramp.update_s:
            self.chamber.write_setpoint_c(round(self._ramp_setpoint_c(now), 3))
            self._ramp_written_s = now

    def follow_software_ramp(self, step: RampSegment) -> None:
        """Keep the software ramp moving until it reaches `step.until_c` (at once if it already has)."""
        assert self._ramp_origin is not None and self.procedure.ramp is not None
        self.machine.go(State.RAMP, setpoint_label(step.setpoint_c))
        t0, start_c = self._ramp_origin
        arrival_s = t0 + abs(step.until_c - start_c) / (self.procedure.ramp.rate_c_per_min / 60.0)
        while self.clock.now() < arrival_s:
            self.write_ramp_setpoint()
            self.read_chamber_c()  # the alarm, and what the progress display shows
            self.report.publish(self.machine.state)
            self.clock.sleep(min(self.procedure.ramp.update_s, arrival_s - self.clock.now()))
        self.write_ramp_setpoint(arrived=True)
        self._reached_s = self.clock.now()

    def ramp(self, step: Ramp) -> None:
        """Set the chamber to the setpoint and wait, within a deadline, for its air to reach it."""
        setpoint_c, soak = step.setpoint_c, self.procedure.soak
        self.machine.go(State.RAMP, setpoint_label(setpoint_c))
        if self.procedure.cooldown is not None and self.procedure.cooldown.chamber == "power-off":
            self.chamber.set_power(True)  # a cool-down switches it off; a resumed one needs it on again
        start_c = self.read_chamber_c()
        self.chamber.write_setpoint_c(setpoint_c)
        ramp_s = abs(setpoint_c - start_c) / (self.rig.chamber.ramp_rate_c_per_min / 60.0)
        timeout_s = soak.ramp_timeout_factor * ramp_s + soak.ramp_timeout_margin_min * 60.0
        self.events.info("ramp", f"ramp {start_c:.1f} → {setpoint_c:g} °C (deadline {format_duration(timeout_s)})")
        def reached() -> bool:
            within = abs(self.read_chamber_c() - setpoint_c) <= soak.chamber_tolerance_c
            self.report.publish(self.machine.state)
            return within

        self._reached_s = wait_until(
            self.clock, reached,
            timeout_s=timeout_s, poll_s=soak.poll_s,
            what=f"chamber ({self.chamber.endpoint}) reaching {setpoint_c:g} °C",
        )

    def soak(self, step: Soak) -> None:
        """Wait for thermal stability, from when the chamber (or the software ramp) reached the setpoint.

        Raises SetpointSkipped when the deadline passes and the procedure says `soak.on_timeout: skip`.
        """
        setpoint_c, label, t_reached = step.setpoint_c, setpoint_label(step.setpoint_c), self._reached_s
        self.machine.go(State.SOAK, label)
        self.temperature_moving = False  # a soak holds the temperature
        criterion = self.procedure.soak
        detector = SoakDetector(criterion, setpoint_c, t_reached)

        def poll() -> bool:
            dut_c = read_temperatures_together(self.sensors)
            detector.add(self.clock.now(), self.read_chamber_c(), dut_c)
            self.report.dut_c = tuple(dut_c.tolist())
            self.report.publish(self.machine.state)
            return detector.is_stable()

        outcome, t_stable = "fault", float("nan")  # what the file says if anything but the deadline stops it
        try:
            t_stable = wait_until(self.clock, poll, timeout_s=criterion.timeout_min * 60.0, poll_s=criterion.poll_s,
                                  what=f"{label}: DUT temperatures {self._stable_means(criterion)}")
            outcome = "stable"
        except WaitTimeout as exc:
            outcome = "timeout"
            if criterion.on_timeout == "abort":
                raise
            timed_out = exc
        finally:
            t, chamber, dut = detector.trace()
            self.settled_dut_c = detector.settled_dut_c() if len(t) else np.full(len(self.sensors), np.nan)
            self.writer.write_soak(SoakTrace(label, setpoint_c, outcome, t, chamber, dut, t_reached, t_stable,
                                             self.settled_dut_c, tuple(s.serial for s in self.sensors)))
        if outcome == "timeout":
            if criterion.on_timeout == "skip":
                n_poses = self.report.poses_left[self.report.setpoint_index]
                self.events.warning("soak", f"{timed_out}; setpoint skipped, its {n_poses} poses not measured "
                                            "(soak.on_timeout: skip)")
                self.report.notify("soak", f"{timed_out}; setpoint skipped (soak.on_timeout: skip)")
                self.report.poses_left[self.report.setpoint_index] = 0
                raise SetpointSkipped(label)
            self.events.warning("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            self.report.notify("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            return
        message = f"{label}: stable after {format_duration(t_stable - t_reached)} at DUT " \
                  f"{np.round(self.settled_dut_c, 2).tolist()} °C ({self._how_stable(detector)})"
        self.events.info("soak", message)
        self.report.notify("soak", message)

    @staticmethod
    def _stable_means(criterion: SoakCriterion) -> str:
        if criterion.criterion == "settling":
            return (f"settled to within {criterion.settle_c:g} °C and {criterion.max_rate_c_per_min:g} °C/min "
                    "(settling criterion)")
        return f"stable within {criterion.band_c:g} °C"

    @staticmethod
    def _how_stable(detector: SoakDetector) -> str:
        if detector.criterion.criterion == "settling":
            settling = detector.settling()
            return (f"still to come ≤ {settling.remaining_c.max():.3f} °C, moving ≤ "
                    f"{settling.rate_c_per_min.max():.4f} °C/min, τ ≤ {settling.time_constant_s.max() / 60:.1f} min")
        return f"spans ≤ {detector.dut_spans_c().max():.2f} °C"

    def read_chamber_c(self) -> float:
        """Chamber air temperature; an active controller alarm is a fault, never a reading to wait out."""
        if self.chamber.alarm_active():
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): controller alarm active")
        self.report.chamber_c = self.chamber.read_temperature_c()
        return self.report.chamber_c
