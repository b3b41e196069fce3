"""Who follows a run besides its file and log — a progress listener and a notifier — and what the runner
tells them: progress snapshots, at every transition, temperature poll and pose, and notifications of its
events. Neither can stop the campaign: a failure is logged, once."""

from __future__ import annotations

from dataclasses import dataclass, field

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.engine.notify import Notification, Notifier
from accelcal_rig.engine.played import DurationEstimate
from accelcal_rig.engine.progress import COOLDOWN_PHASES, PHASES, Progress, ProgressListener
from accelcal_rig.engine.states import State
from accelcal_rig.plan.compile import Plan

#: States in which there is measuring left to do (and an estimate of the time it takes).
MEASURING_STATES = frozenset({State.IDLE, State.PREFLIGHT, State.RAMP, State.SOAK, State.MOVE, State.SETTLE,
                              State.ACQUIRE, State.STORE, State.COOL})


@dataclass(frozen=True)
class Audience:
    """A progress listener (the estimate gives it the time left), a notifier, and the campaign's name."""

    progress: ProgressListener | None = None
    estimate: DurationEstimate | None = None
    notifier: Notifier | None = None
    campaign: str = ""


@dataclass
class Reporter:
    """The runner's account to its audience: where in the plan it is and what it last read."""

    audience: Audience
    plan: Plan
    procedure_name: str
    clock: Clock
    cooldown: bool
    #: Poses still to measure at each setpoint (the estimate's input).
    poses_left: list[int]
    poses_done: int
    setpoint_index: int = -1
    setpoint_start_s: float = 0.0
    chamber_c: float | None = None
    dut_c: tuple[float, ...] = ()
    _phase: tuple[str, float] = ("idle", 0.0)  # (phase, clock time it began)
    _failed: bool = field(default=False, repr=False)

    def phase_of(self, state: State) -> str:
        """The phase an operator names a state by (the poses' states are one phase)."""
        return (COOLDOWN_PHASES if self.cooldown else PHASES).get(str(state), str(state))

    def begin_setpoint(self, setpoint_c: float) -> None:
        self.setpoint_index = self.plan.setpoints_c.index(setpoint_c)
        self.setpoint_start_s = self.clock.now()

    def pose_stored(self, chamber_c: float, dut_c: tuple[float, ...]) -> None:
        """A pose is in the file: count it, and keep the temperatures read with it."""
        self.poses_done += 1
        self.poses_left[self.setpoint_index] -= 1
        self.chamber_c, self.dut_c = chamber_c, dut_c

    def skip_setpoint(self) -> int:
        """The current setpoint's poses will not be measured: how many that is."""
        skipped, self.poses_left[self.setpoint_index] = self.poses_left[self.setpoint_index], 0
        return skipped

    def remaining_s(self, state: State) -> float | None:
        """The estimate of the time left, while there is measuring left to do."""
        estimate = self.audience.estimate
        if estimate is None or state not in MEASURING_STATES:
            return None
        started = self.setpoint_index >= 0
        return estimate.remaining_s(self.poses_left, max(self.setpoint_index, 0),
                                    self.clock.now() - self.setpoint_start_s if started else 0.0,
                                    self.phase_of(state) in ("poses", "cool"))

    def publish(self, state: State) -> None:
        """Hand the progress listener a snapshot; a listener that fails is reported once and ignored."""
        if self.audience.progress is None or self._failed:
            return
        now = self.clock.now()
        phase = self.phase_of(state)
        if phase != self._phase[0]:
            self._phase = (phase, now)
        index = self.setpoint_index
        active = 0 <= index and state in MEASURING_STATES
        try:
            self.audience.progress(Progress(
                state=str(state), phase=phase, setpoint_c=self.plan.setpoints_c[index] if active else None,
                setpoint_number=index + 1, setpoints_total=len(self.plan.setpoints_c),
                phase_elapsed_s=now - self._phase[1], chamber_c=self.chamber_c, dut_c=self.dut_c,
                poses_done=self.poses_done, poses_total=len(self.plan.pose_steps), clock_s=now,
                remaining_s=self.remaining_s(state)))
        except Exception as exc:  # noqa: BLE001 - a display must never stop a campaign
            self._failed = True
            LOGGER.error("progress display failed, no more progress shown: %s", exc)

    def notify(self, event: str, message: str) -> None:
        if self.audience.notifier is not None:
            self.audience.notifier.send(Notification(event, message, self.audience.campaign, self.procedure_name,
                                                     self.clock.now(), self.poses_done, len(self.plan.pose_steps)))
