"""The frost steps of a plan: the chamber's dry-air purge, and the wait, after a warming step, until every
DUT is far enough above the chamber air's dew point that nothing condenses on it. Both go to the event log."""

from __future__ import annotations

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.humidity import dew_point_c
from accelcal_rig.core.waits import wait_until
from accelcal_rig.engine.events import EventLog
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import has_purge, humidity_pct, set_purge
from accelcal_rig.instruments.interfaces import Accelerometer, Chamber
from accelcal_rig.plan.compile import Plan, setpoint_label
from accelcal_rig.plan.steps import AwaitDewPointMargin, SetPurge


class FrostSteps:
    def __init__(self, procedure: Procedure, rig: RigConfig, chamber: Chamber, sensors: list[Accelerometer],
                 clock: Clock, events: EventLog) -> None:
        self.frost, self.poll_s = procedure.frost, procedure.soak.poll_s
        self.configured_dew_point_c = rig.chamber.dew_point_c
        self.chamber, self.sensors, self.clock, self.events = chamber, sensors, clock, events

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
        side = "below" if step.on else "at or above"
        self.events.info("purge", f"dry-air purge {'on' if step.on else 'off'} for {setpoint_label(step.setpoint_c)} "
                                  f"({side} {self.frost.purge_below_c:g} °C)")

    def await_dew_point_margin(self, step: AwaitDewPointMargin) -> None:
        """Poll the DUTs' own temperature sensors and the dew point until the coldest DUT has the margin."""
        assert self.frost.dew_point_margin_c is not None
        required = self.frost.dew_point_margin_c
        reported: list[bool] = []

        def dry() -> bool:
            dew_point, source = self._dew_point()
            coldest_c, serial = min((s.read_temperature_c(), s.serial) for s in self.sensors)
            margin = coldest_c - dew_point
            if margin >= required:
                self.events.info("dew-point", f"{setpoint_label(step.setpoint_c)}: coldest DUT {serial} "
                                              f"{coldest_c:.1f} °C, {margin:.1f} °C above the dew point "
                                              f"{dew_point:.1f} °C ({source}): poses may begin")
                return True
            if not reported:
                reported.append(True)
                self.events.warning("dew-point", f"{setpoint_label(step.setpoint_c)}: coldest DUT {serial} "
                                                 f"{coldest_c:.1f} °C is only {margin:.1f} °C above the dew point "
                                                 f"{dew_point:.1f} °C ({source}), {required:g} °C needed: waiting")
            return False

        wait_until(self.clock, dry, timeout_s=self.frost.dew_point_timeout_min * 60.0, poll_s=self.poll_s,
                   what=f"{setpoint_label(step.setpoint_c)}: DUTs {required:g} °C above the chamber's dew point")

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
