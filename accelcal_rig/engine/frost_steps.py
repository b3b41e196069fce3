"""The frost steps of a plan: the chamber's dry-air purge, and the wait, after a warming step, until every
DUT is far enough above the point where the chamber air's moisture would settle on it (the dew point, or
below 0 °C the frost point) that nothing condenses or freezes on it. Both go to the event log."""

from __future__ import annotations

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.humidity import condensation_point_c, dew_point_c
from accelcal_rig.core.waits import wait_until
from accelcal_rig.engine.audience import Reporter
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.thermal_steps import ThermalSteps
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import has_purge, humidity_pct, set_purge
from accelcal_rig.instruments.interfaces import Accelerometer
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.plan.compile import Plan, setpoint_label
from accelcal_rig.plan.steps import AwaitDewPointMargin, SetPurge


class FrostSteps:
    def __init__(self, procedure: Procedure, rig: RigConfig, thermal: ThermalSteps, sensors: list[Accelerometer],
                 clock: Clock, events: EventLog, report: Reporter) -> None:
        self.frost, self.poll_s = procedure.frost, procedure.soak.poll_s
        self.configured_dew_point_c = rig.chamber.dew_point_c
        self.thermal, self.chamber = thermal, thermal.chamber
        self.sensors, self.clock, self.events, self.report = sensors, clock, events, report
        #: Whether this run last switched the purge on (None: it has not switched it).
        self.purge_on: bool | None = None

    def preflight(self, plan: Plan) -> None:
        """Whatever the plan's frost steps need from the chamber, or a fault before anything moves."""
        steps = [step for stage in plan.stages for step in (*stage.entry, *stage.restart_entry)]
        if any(isinstance(s, SetPurge) for s in steps) and not has_purge(self.chamber):
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): the procedure holds the dry-air purge on "
                                  "below frost.purge_below_c, and the chamber's profile has no purge output")
        if any(isinstance(s, AwaitDewPointMargin) for s in steps):
            dew_point, source = self._dew_point()  # a controller that cannot say is a fault now, not at -40 °C
            self.events.info("preflight", f"chamber: dew point {dew_point:.1f} °C ({source})")

    def set_purge(self, step: SetPurge) -> None:
        set_purge(self.chamber, step.on)
        self.purge_on = step.on
        side = "below" if step.on else "at or above"
        self.events.info("purge", f"dry-air purge {'on' if step.on else 'off'} for {setpoint_label(step.setpoint_c)} "
                                  f"({side} {self.frost.purge_below_c:g} °C)")

    def note_purge_left_on(self) -> None:
        """The safe state leaves the purge as it is (dry air while the chamber warms to its safe setpoint is
        what keeps the fixture dry): say so, so that nobody leaves it running unawares."""
        if self.purge_on:
            self.events.warning("purge", "dry-air purge left ON: switch it off once the chamber is at its safe "
                                         "setpoint and the fixture is warm")

    def await_dew_point_margin(self, step: AwaitDewPointMargin) -> None:
        """Poll the DUTs' own temperature sensors, the chamber (its alarm) and the dew point until the coldest
        DUT has the margin. A software ramp keeps moving meanwhile: the air warming past the room's dew point
        is what gives the margin (held, saturated air would never give it)."""
        assert self.frost.dew_point_margin_c is not None
        required = self.frost.dew_point_margin_c
        label = setpoint_label(step.setpoint_c)
        reported: list[bool] = []

        def dry() -> bool:
            self.thermal.write_ramp_setpoint()  # no-op unless a software ramp runs
            self.thermal.read_chamber_c()  # an active alarm is a fault, never a reading to wait out
            dew_point, source = self._dew_point()
            settles_c = condensation_point_c(dew_point)
            where = (f"dew point {dew_point:.1f} °C" if settles_c == dew_point
                     else f"frost point {settles_c:.1f} °C (dew point {dew_point:.1f} °C)") + f" ({source})"
            coldest_c, serial = min(zip(read_temperatures_together(self.sensors).tolist(),
                                        (s.serial for s in self.sensors)))
            margin = coldest_c - settles_c
            self.report.publish(self.thermal.machine.state)
            if margin >= required:
                self.events.info("dew-point", f"{label}: coldest DUT {serial} {coldest_c:.1f} °C, {margin:.1f} °C "
                                              f"above the {where}: poses may begin")
                return True
            if not reported:
                reported.append(True)
                self.events.warning("dew-point", f"{label}: coldest DUT {serial} {coldest_c:.1f} °C is only "
                                                 f"{margin:.1f} °C above the {where}, {required:g} °C needed: "
                                                 "waiting")
            return False

        wait_until(self.clock, dry, timeout_s=self.frost.dew_point_timeout_min * 60.0, poll_s=self.poll_s,
                   what=f"{label}: DUTs {required:g} °C above the chamber's dew point")

    def _dew_point(self) -> tuple[float, str]:
        """The chamber air's dew point and where it comes from: the configured value, else the controller's
        humidity reading at its air temperature."""
        if self.configured_dew_point_c is not None:
            return self.configured_dew_point_c, "configured"
        relative_humidity = humidity_pct(self.chamber)
        if relative_humidity is None:
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): the procedure needs the air's dew point "
                                  "(frost.dew_point_margin_c); the controller has no humidity reading: set "
                                  "chamber.dew_point_c in the rig config")
        air_c = self.chamber.read_temperature_c()
        try:
            return dew_point_c(air_c, relative_humidity), f"{relative_humidity:.1f} % RH at {air_c:.1f} °C"
        except ValueError as exc:
            raise InstrumentError(f"chamber ({self.chamber.endpoint}): {exc}") from None
