"""The frost steps of a plan: the chamber's dry-air purge, and the wait, after a warming step, until every
DUT is far enough above the point where the chamber air's moisture would settle on it (the dew point, or
below 0 °C the frost point) that nothing condenses or freezes on it. Both go to the event log."""

from __future__ import annotations

import numpy as np

from accelcal_rig.core.humidity import condensation_point_c, dew_point_c
from accelcal_rig.core.waits import wait_until
from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import has_purge, humidity_pct, set_purge
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.plan.compile import setpoint_label
from accelcal_rig.plan.steps import AwaitDewPointMargin, SetPurge


def frost_preflight(run: RunContext) -> None:
    """Whatever the plan's frost steps need from the chamber, or a fault before anything moves."""
    chamber = run.chamber
    steps = [step for stage in run.plan.stages for step in (*stage.entry, *stage.restart_entry)]
    if any(isinstance(s, SetPurge) for s in steps) and not has_purge(chamber):
        raise InstrumentError(f"chamber ({chamber.endpoint}): the procedure holds the dry-air purge on "
                              "below frost.purge_below_c, and the chamber's profile has no purge output")
    if any(isinstance(s, AwaitDewPointMargin) for s in steps):
        dew_point, source = _dew_point(run)  # a controller that cannot say is a fault now, not at -40 °C
        run.events.info("preflight", f"chamber: dew point {dew_point:.1f} °C ({source})")


def note_purge_left_on(run: RunContext) -> None:
    """The safe state leaves the purge as it is (dry air while the chamber warms to its safe setpoint is
    what keeps the fixture dry): say so, so that nobody leaves it running unawares."""
    if run.purge_on:
        run.events.warning("purge", "dry-air purge left ON: switch it off once the chamber is at its safe "
                                    "setpoint and the fixture is warm")


class SetPurgeStep:
    def run(self, step: SetPurge, run: RunContext) -> None:
        set_purge(run.chamber, step.on)
        run.purge_on = step.on
        side = "below" if step.on else "at or above"
        run.events.info("purge", f"dry-air purge {'on' if step.on else 'off'} for {setpoint_label(step.setpoint_c)} "
                                 f"({side} {run.procedure.frost.purge_below_c:g} °C)")

    def estimate(self, step: SetPurge, played: PlayedRig) -> None:
        """One register or line written: no time worth counting."""


class AwaitDewPointMarginStep:
    def run(self, step: AwaitDewPointMargin, run: RunContext) -> None:
        """Poll the DUTs' own temperature sensors, the chamber (its alarm) and the dew point until the coldest
        DUT has the margin. A software ramp keeps moving meanwhile: the air warming past the room's dew point
        is what gives the margin (held, saturated air would never give it)."""
        frost = run.procedure.frost
        assert frost.dew_point_margin_c is not None
        required = frost.dew_point_margin_c
        label = setpoint_label(step.setpoint_c)
        reported: list[bool] = []

        def dry() -> bool:
            run.write_ramp_setpoint()  # no-op unless a software ramp runs
            run.read_chamber_c()  # an active alarm is a fault, never a reading to wait out
            dew_point, source = _dew_point(run)
            settles_c = condensation_point_c(dew_point)
            where = (f"dew point {dew_point:.1f} °C" if settles_c == dew_point
                     else f"frost point {settles_c:.1f} °C (dew point {dew_point:.1f} °C)") + f" ({source})"
            coldest_c, serial = min(zip(read_temperatures_together(run.sensors).tolist(),
                                        (s.serial for s in run.sensors)))
            margin = coldest_c - settles_c
            run.report.publish(run.machine.state)
            if margin >= required:
                run.events.info("dew-point", f"{label}: coldest DUT {serial} {coldest_c:.1f} °C, {margin:.1f} °C "
                                             f"above the {where}: poses may begin")
                return True
            if not reported:
                reported.append(True)
                run.events.warning("dew-point", f"{label}: coldest DUT {serial} {coldest_c:.1f} °C is only "
                                                f"{margin:.1f} °C above the {where}, {required:g} °C needed: "
                                                "waiting")
            return False

        wait_until(run.clock, dry, timeout_s=frost.dew_point_timeout_min * 60.0, poll_s=run.procedure.soak.poll_s,
                   what=f"{label}: DUTs {required:g} °C above the chamber's dew point")

    def estimate(self, step: AwaitDewPointMargin, played: PlayedRig) -> None:
        """With the rig's configured dew point: the model's coldest DUT polled until it has the margin (a
        software ramp moving meanwhile), within the deadline. A dew point read off the controller's humidity
        is not known in advance: then no time is counted."""
        frost, dew_point_c = played.procedure.frost, played.rig.chamber.dew_point_c
        if dew_point_c is None or frost.dew_point_margin_c is None:
            return
        wanted_c = condensation_point_c(dew_point_c) + frost.dew_point_margin_c
        poll_s, start_s = played.procedure.soak.poll_s, played.t_s
        t = start_s
        while float(np.min(played.thermal.duts_c(t))) < wanted_c and t - start_s < frost.dew_point_timeout_min * 60:
            if played.software_ramp is not None:
                played.follow_software_ramp(t, t + poll_s - 1e-6)
            t += poll_s
        played.wait("soak", t - start_s)


def _dew_point(run: RunContext) -> tuple[float, str]:
    """The chamber air's dew point and where it comes from: the configured value, else the controller's
    humidity reading at its air temperature."""
    configured, chamber = run.rig.chamber.dew_point_c, run.chamber
    if configured is not None:
        return configured, "configured"
    relative_humidity = humidity_pct(chamber)
    if relative_humidity is None:
        raise InstrumentError(f"chamber ({chamber.endpoint}): the procedure needs the air's dew point "
                              "(frost.dew_point_margin_c); the controller has no humidity reading: set "
                              "chamber.dew_point_c in the rig config")
    air_c = chamber.read_temperature_c()
    try:
        return dew_point_c(air_c, relative_humidity), f"{relative_humidity:.1f} % RH at {air_c:.1f} °C"
    except ValueError as exc:
        raise InstrumentError(f"chamber ({chamber.endpoint}): {exc}") from None


SET_PURGE: StepHandler[SetPurge] = SetPurgeStep()
AWAIT_DEW_POINT_MARGIN: StepHandler[AwaitDewPointMargin] = AwaitDewPointMarginStep()
