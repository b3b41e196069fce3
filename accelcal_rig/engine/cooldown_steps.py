"""A cool-down's records: the first at the setpoint, then the chamber is let go (switched off, or set to
ambient) and a record follows every `record_every_s` while the DUTs cool at the pose they hold.

A resumed cool-down records its missing blocks on a fresh schedule, after a fresh soak.
"""

from __future__ import annotations

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.core.clock import Clock
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.pose_steps import PoseSteps
from accelcal_rig.engine.states import State, StateMachine
from accelcal_rig.engine.thermal_steps import ThermalSteps
from accelcal_rig.instruments.interfaces import Chamber
from accelcal_rig.plan.steps import CooldownRecord


class CooldownSteps:
    def __init__(self, procedure: Procedure, chamber: Chamber, clock: Clock, events: EventLog,
                 machine: StateMachine, thermal: ThermalSteps, poses: PoseSteps) -> None:
        self.procedure, self.chamber, self.clock, self.events, self.machine = procedure, chamber, clock, events, machine
        self.thermal, self.poses = thermal, poses
        #: When this run let the chamber go (None: not yet), and the records taken since.
        self._released_s: float | None = None
        self._since_release = 0

    def record(self, step: CooldownRecord) -> None:
        cooldown = self.procedure.cooldown
        assert cooldown is not None
        if self._released_s is None:
            self.thermal.temperature_moving = True
            self.poses.measure(step)
            self._released_s = self.clock.now()
            if cooldown.chamber == "power-off":
                self.chamber.set_power(False)
                self.events.info("cooldown", "chamber switched off: the DUTs cool freely; recording every "
                                             f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
            else:
                self.chamber.write_setpoint_c(cooldown.ambient_c)
                self.events.info("cooldown", f"chamber set to ambient {cooldown.ambient_c:g} °C; recording every "
                                             f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
            return
        self._since_release += 1
        self.machine.go(State.COOL, step.key)
        self.clock.sleep(max(self._released_s + self._since_release * cooldown.record_every_s - self.clock.now(), 0.0))
        self.poses.measure(step)
