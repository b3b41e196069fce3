"""The chamber's steps of a plan: ramping to a setpoint, soaking until the DUTs are stable, the ramp method's
software ramp — each run on the rig and estimated against its model, and what they leave for the poses
(the settled DUT temperatures, whether the temperatures move on purpose) in the run's `dut` state."""

from __future__ import annotations

import numpy as np

from accelcal_rig.config.procedure import SoakCriterion
from accelcal_rig.core.formatting import format_duration, format_fixed
from accelcal_rig.core.waits import wait_until
from accelcal_rig.engine.played import EstimateEnds, PlayedRig, SoftwareRampPlayed
from accelcal_rig.engine.run_context import RunContext, SoftwareRamp
from accelcal_rig.engine.soak import SoakDetector
from accelcal_rig.engine.soak_estimate import soak_duration
from accelcal_rig.engine.states import State
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.errors import WaitTimeout
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.plan.compile import setpoint_label
from accelcal_rig.plan.steps import AdvanceRamp, Ramp, RampSegment, Soak, StartSoftwareRamp
from accelcal_rig.store.records import SoakTrace


class SetpointSkipped(Exception):
    """A soak ran out of time and the procedure says to skip its setpoint (`soak.on_timeout: skip`)."""


class RampStep:
    def run(self, step: Ramp, run: RunContext) -> None:
        """Set the chamber to the setpoint and wait, within a deadline, for its air to reach it."""
        setpoint_c, soak, chamber = step.setpoint_c, run.procedure.soak, run.chamber
        run.machine.go(State.RAMP, setpoint_label(setpoint_c))
        if run.procedure.cooldown is not None and run.procedure.cooldown.chamber == "power-off":
            chamber.set_power(True)  # a cool-down switches it off; a resumed one needs it on again
        start_c = run.read_chamber_c()
        chamber.write_setpoint_c(setpoint_c)
        trace_t, trace_c = run.dut.ramp_t_s, run.dut.ramp_chamber_c
        trace_t[:], trace_c[:] = [run.clock.now()], [start_c]
        ramp_s = abs(setpoint_c - start_c) / (run.rig.chamber.ramp_rate_c_per_min / 60.0)
        timeout_s = soak.ramp_timeout_factor * ramp_s + soak.ramp_timeout_margin_min * 60.0
        run.events.info("ramp", f"ramp {format_fixed(start_c)} → {setpoint_c:g} °C (deadline {format_duration(timeout_s)})")

        def reached() -> bool:
            air_c = run.read_chamber_c()
            trace_t.append(run.clock.now())
            trace_c.append(air_c)
            within = abs(air_c - setpoint_c) <= soak.chamber_tolerance_c
            run.report.publish(run.machine.state)
            return within

        run.dut.reached_s = wait_until(run.clock, reached, timeout_s=timeout_s, poll_s=soak.poll_s,
                                       what=f"chamber ({chamber.endpoint}) reaching {setpoint_c:g} °C")

    def estimate(self, step: Ramp, played: PlayedRig) -> None:
        """The chamber's air polled as the engine polls it, to the same deadline; past it the engine aborts."""
        setpoint_c, soak, thermal = step.setpoint_c, played.procedure.soak, played.thermal
        played.software_ramp = None
        start_s = t = played.t_s
        thermal.set_setpoint(t, setpoint_c)
        deadline_s = t + soak.ramp_timeout_factor * abs(setpoint_c - thermal.air_c(t)) / (
            played.rig.chamber.ramp_rate_c_per_min / 60.0) + soak.ramp_timeout_margin_min * 60.0
        while abs(thermal.air_c(t) - setpoint_c) > soak.chamber_tolerance_c and t < deadline_s:
            t = min(t + soak.poll_s, deadline_s)
        played.wait("ramp", t - start_s)
        if abs(thermal.air_c(t) - setpoint_c) > soak.chamber_tolerance_c:
            played.tally.outcome = "ramp timeout"
            raise EstimateEnds(setpoint_label(setpoint_c))


class SoakStep:
    def run(self, step: Soak, run: RunContext) -> None:
        """Wait for thermal stability, from when the chamber (or the software ramp) reached the setpoint.

        Raises SetpointSkipped when the deadline passes and the procedure says `soak.on_timeout: skip`.
        """
        setpoint_c, label, t_reached = step.setpoint_c, setpoint_label(step.setpoint_c), run.dut.reached_s
        run.machine.go(State.SOAK, label)
        run.dut.moving = False  # a soak holds the temperature
        criterion = run.procedure.soak
        detector = SoakDetector(criterion, setpoint_c, t_reached)

        def poll() -> bool:
            dut_c = read_temperatures_together(run.sensors)
            detector.add(run.clock.now(), run.read_chamber_c(), dut_c)
            run.report.dut_c = tuple(dut_c.tolist())
            run.report.publish(run.machine.state)
            return detector.is_stable()

        outcome, t_stable = "fault", float("nan")  # what the file says if anything but the deadline stops it
        try:
            t_stable = wait_until(run.clock, poll, timeout_s=criterion.timeout_min * 60.0, poll_s=criterion.poll_s,
                                  what=f"{label}: DUT temperatures {_stable_means(criterion)}")
            outcome = "stable"
        except WaitTimeout as exc:
            outcome = "timeout"
            if criterion.on_timeout == "abort":
                raise
            timed_out = exc
        finally:
            t, chamber, dut = detector.trace()
            run.dut.settled_c = detector.settled_dut_c() if len(t) else np.full(len(run.sensors), np.nan)
            run.writer.write_soak(SoakTrace(label, setpoint_c, outcome, t, chamber, dut, t_reached, t_stable,
                                            run.dut.settled_c, tuple(s.serial for s in run.sensors),
                                            np.array(run.dut.ramp_t_s), np.array(run.dut.ramp_chamber_c)))
            run.dut.ramp_t_s.clear()  # each ramp's polls go with its own soak
            run.dut.ramp_chamber_c.clear()
        if outcome == "timeout":
            if criterion.on_timeout == "skip":
                n_poses = run.report.skip_setpoint()
                run.events.warning("soak", f"{timed_out}; setpoint skipped, its {n_poses} poses not measured "
                                           "(soak.on_timeout: skip)")
                run.report.notify("soak", f"{timed_out}; setpoint skipped (soak.on_timeout: skip)")
                raise SetpointSkipped(label)
            run.events.warning("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            run.report.notify("soak", f"{timed_out}; measuring its poses anyway (soak.on_timeout: proceed)")
            return
        message = f"{label}: stable after {format_duration(t_stable - t_reached)} at DUT " \
                  f"{np.round(run.dut.settled_c, 2).tolist()} °C ({_how_stable(detector)})"
        run.events.info("soak", message)
        run.report.notify("soak", message)

    def estimate(self, step: Soak, played: PlayedRig) -> None:
        soak_s, outcome, settled = soak_duration(played.thermal, played.procedure, step.setpoint_c, played.t_s,
                                                 played.readers)
        played.wait("soak", soak_s)
        played.tally.outcome, played.tally.settled_dut_c = outcome, settled


def _stable_means(criterion: SoakCriterion) -> str:
    if criterion.criterion == "settling":
        return (f"settled to within {criterion.settle_c:g} °C and {criterion.max_rate_c_per_min:g} °C/min "
                "(settling criterion)")
    return f"stable within {criterion.band_c:g} °C"


def _how_stable(detector: SoakDetector) -> str:
    if detector.criterion.criterion == "settling":
        settling = detector.settling()
        return (f"still to come ≤ {settling.remaining_c.max():.3f} °C, moving ≤ "
                f"{settling.rate_c_per_min.max():.4f} °C/min, τ ≤ {settling.time_constant_s.max() / 60:.1f} min")
    return f"spans ≤ {detector.dut_spans_c().max():.2f} °C"


class StartSoftwareRampStep:
    def run(self, step: StartSoftwareRamp, run: RunContext) -> None:
        """From the step's setpoint on, move the chamber setpoint at the procedure's rate towards the step's
        target; the poses in between follow the ramp."""
        settings = run.procedure.ramp
        assert settings is not None
        run.dut.software_ramp = SoftwareRamp(settings, run.clock.now(), step.setpoint_c, step.toward_c)
        run.dut.moving = True
        run.events.info("ramp", f"ramp method: chamber setpoint moving {step.setpoint_c:g} → {step.toward_c:g} °C "
                                f"at {settings.rate_c_per_min:g} °C/min, poses taken as it goes")

    def estimate(self, step: StartSoftwareRamp, played: PlayedRig) -> None:
        played.software_ramp = SoftwareRampPlayed(played.t_s, step.setpoint_c, step.toward_c)


class RampSegmentStep:
    def run(self, step: RampSegment, run: RunContext) -> None:
        """Keep the software ramp moving until it reaches `step.until_c` (at once if it already has)."""
        ramp = run.dut.software_ramp
        assert ramp is not None
        run.machine.go(State.RAMP, setpoint_label(step.setpoint_c))
        arrival_s = ramp.arrival_s(step.until_c)
        while run.clock.now() < arrival_s:
            run.write_ramp_setpoint()
            run.read_chamber_c()  # the alarm, and what the progress display shows
            run.report.publish(run.machine.state)
            run.clock.sleep(min(ramp.settings.update_s, arrival_s - run.clock.now()))
        run.write_ramp_setpoint(arrived=True)
        run.dut.reached_s = run.clock.now()

    def estimate(self, step: RampSegment, played: PlayedRig) -> None:
        ramp, settings = played.software_ramp, played.procedure.ramp
        if ramp is None or settings is None:
            return
        wait_s = max(ramp.started_s + abs(step.until_c - ramp.from_c) / (settings.rate_c_per_min / 60.0)
                     - played.t_s, 0.0)
        played.follow_software_ramp(played.t_s, played.t_s + wait_s)
        played.wait("ramp", wait_s)


class AdvanceRampStep:
    def run(self, step: AdvanceRamp, run: RunContext) -> None:
        """Between poses on the ramp: write its current setpoint."""
        run.write_ramp_setpoint()

    def estimate(self, step: AdvanceRamp, played: PlayedRig) -> None:
        """Takes no time of its own: the ramp moves with the setpoint's poses (PlayedRig.end_setpoint)."""


RAMP: StepHandler[Ramp] = RampStep()
SOAK: StepHandler[Soak] = SoakStep()
START_SOFTWARE_RAMP: StepHandler[StartSoftwareRamp] = StartSoftwareRampStep()
RAMP_SEGMENT: StepHandler[RampSegment] = RampSegmentStep()
ADVANCE_RAMP: StepHandler[AdvanceRamp] = AdvanceRampStep()
