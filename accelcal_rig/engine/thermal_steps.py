"""The chamber's part of a campaign: ramping to a setpoint, soaking until the DUTs are stable, the ramp
method's software ramp, a free cool-down — and what they leave for the poses (the settled DUT temperatures,
whether the temperatures move on purpose)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from accelcal_rig.config.procedure import Procedure
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
from accelcal_rig.plan.compile import Plan, PlanStep
from accelcal_rig.store.records import SoakTrace
from accelcal_rig.store.writer import CampaignWriter


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
        self._ramp_written_s = float("-inf")

    @property
    def ramping(self) -> bool:
        """The ramp method's software ramp is running."""
        return self._ramp_origin is not None

    def start_software_ramp(self, setpoint_c: float) -> None:
        """From the soak at `setpoint_c` on, move the chamber setpoint at the procedure's rate towards the
        last setpoint, where it soaks again; the poses in between follow the ramp."""
        assert self.procedure.ramp is not None
        self._ramp_origin = (self.clock.now(), setpoint_c)
        self.temperature_moving = True
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

    def cycle_start_c(self, setpoint_c: float) -> float:
        """A setpoint's poses begin half-way from the previous setpoint."""
        index = self.plan.setpoints_c.index(setpoint_c)
        return 0.5 * (self.plan.setpoints_c[index - 1] + setpoint_c) if index else setpoint_c

    def advance_software_ramp(self) -> None:
        """Write the ramp's current setpoint, at most every `ramp.update_s`."""
        if self._ramp_origin is None:
            return
        assert self.procedure.ramp is not None
        now = self.clock.now()
        if now - self._ramp_written_s >= self.procedure.ramp.update_s:
            self.chamber.write_setpoint_c(round(self._ramp_setpoint_c(now), 3))
            self._ramp_written_s = now

    def follow_ramp_to(self, target_c: float) -> None:
        """Keep the software ramp moving until it reaches `target_c` (at once if it already has)."""
        assert self._ramp_origin is not None and self.procedure.ramp is not None
        t0, start_c = self._ramp_origin
        arrival_s = t0 + abs(target_c - start_c) / (self.procedure.ramp.rate_c_per_min / 60.0)
        while self.clock.now() < arrival_s:
            self.advance_software_ramp()
            self.read_chamber_c()  # the alarm, and what the progress display shows
            self.report.publish(self.machine.state)
            self.clock.sleep(min(self.procedure.ramp.update_s, arrival_s - self.clock.now()))
        self.advance_software_ramp()

    def cool_down(self, steps: list[PlanStep], measure: Callable[[PlanStep], None]) -> None:
        """Hold the pose, record once at the setpoint, let the chamber go, record on schedule while the DUTs
        cool. A resumed cool-down records its missing blocks on a fresh schedule after a fresh soak."""
        cooldown = self.procedure.cooldown
        assert cooldown is not None
        released_s = self.clock.now()
        self.temperature_moving = True
        for index, step in enumerate(steps):
            if index:  # every record_every_s from the moment the chamber was let go
                self.machine.go(State.COOL, step.key)
                self.clock.sleep(max(released_s + index * cooldown.record_every_s - self.clock.now(), 0.0))
            measure(step)
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
        self.temperature_moving = False

    def ramp(self, setpoint_c: float) -> float:
        soak = self.procedure.soak
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

        t_reached = wait_until(
            self.clock, reached,
            timeout_s=timeout_s, poll_s=soak.poll_s,
            what=f"chamber ({self.chamber.endpoint}) reaching {setpoint_c:g} °C",
        )
        return t_reached

    def soak(self, setpoint_c: float, label: str, t_reached: float, n_poses: int) -> bool:
        """Wait for thermal stability; False when the setpoint is to be skipped (`soak.on_timeout: skip`)."""
        criterion = self.procedure.soak
        detector = SoakDetector(criterion, setpoint_c, t_reached)

        def poll() -> bool:
            dut_c = np.array([s.read_temperature_c() for s in self.sensors])
            detector.add(self.clock.now(), self.read_chamber_c(), dut_c)
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
            self.settled_dut_c = detector.settled_dut_c() if len(t) else np.full(len(self.sensors), np.nan)
            self.writer.write_soak(SoakTrace(label, setpoint_c, outcome, t, chamber, dut, t_reached, t_stable,
                                             self.settled_dut_c, tuple(s.serial for s in self.sensors)))
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
                   f"{np.round(self.settled_dut_c, 2).tolist()} °C (spans ≤ {spans.max():.2f} °C)")
        self.events.info("soak", message)
        self.report.notify("soak", message)
        return True

    def read_chamber_c(self) -> float:
        """Chamber air temperature; an active controller alarm is a fault, never a reading to wait out."""
        if self.chamber.alarm_active():
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): controller alarm active")
        self.report.chamber_c = self.chamber.read_temperature_c()
        return self.report.chamber_c
