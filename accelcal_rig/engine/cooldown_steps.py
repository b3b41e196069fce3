"""A cool-down's records: the first at the setpoint, then the chamber is let go (switched off, or set to
ambient) and a record follows every `record_every_s` while the DUTs cool at the pose they hold.

A resumed cool-down records its missing blocks on a fresh schedule, after a fresh soak.
"""

from __future__ import annotations

from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.pose_steps import measure
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.states import State
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.plan.steps import CooldownRecord


class CooldownRecordStep:
    def run(self, step: CooldownRecord, run: RunContext) -> None:
        cooldown, state = run.procedure.cooldown, run.cooldown
        assert cooldown is not None
        if state.released_s is None:
            run.dut.moving = True
            measure(step, run)
            state.released_s = run.clock.now()
            if cooldown.chamber == "power-off":
                run.chamber.set_power(False)
                run.events.info("cooldown", "chamber switched off: the DUTs cool freely; recording every "
                                            f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
            else:
                run.chamber.write_setpoint_c(cooldown.ambient_c)
                run.events.info("cooldown", f"chamber set to ambient {cooldown.ambient_c:g} °C; recording every "
                                            f"{cooldown.record_every_s:g} s for {cooldown.duration_min:g} min")
            return
        state.since_release += 1
        run.machine.go(State.COOL, step.key)
        run.clock.sleep(max(state.released_s + state.since_release * cooldown.record_every_s - run.clock.now(), 0.0))
        measure(step, run)

    def estimate(self, step: CooldownRecord, played: PlayedRig) -> None:
        """The first record is a pose; the others come on the schedule that starts when it is taken."""
        cooldown = played.procedure.cooldown
        assert cooldown is not None
        travel_s = played.travel_to(step.pose.angles_deg)
        first = played.tally.records == 0
        played.tally.records += 1
        played.wait("poses", travel_s + (played.pose_fixed_s if first else cooldown.record_every_s))


COOLDOWN_RECORD: StepHandler[CooldownRecord] = CooldownRecordStep()
