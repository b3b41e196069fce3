"""Engine states and the transition table: the only moves the engine may make, each one logged."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from enum import StrEnum

from accelcal_rig.store.records import StoredEvent


class State(StrEnum):
    IDLE = "idle"
    PREFLIGHT = "preflight"
    RAMP = "ramp"
    SOAK = "soak"
    MOVE = "move"
    SETTLE = "settle"
    ACQUIRE = "acquire"
    STORE = "store"
    COOL = "cool"          # a cool-down: waiting for its next record
    SAFE = "safe"
    FIT = "fit"
    DONE = "done"
    ABORTING = "aborting"
    ABORTED = "aborted"


ACTIVE_STATES = frozenset({State.IDLE, State.PREFLIGHT, State.RAMP, State.SOAK, State.MOVE, State.SETTLE, State.ACQUIRE,
           State.STORE, State.COOL, State.FIT})

TRANSITIONS: dict[State, frozenset[State]] = {
    State.IDLE: frozenset({State.PREFLIGHT}),
    State.PREFLIGHT: frozenset({State.RAMP, State.SAFE}),  # SAFE: a resumed run with every pose stored
    State.RAMP: frozenset({State.SOAK, State.MOVE}),  # MOVE: the ramp method, poses while ramping
    State.SOAK: frozenset({State.MOVE, State.RAMP, State.SAFE}),  # RAMP, SAFE: a setpoint skipped
    State.MOVE: frozenset({State.SETTLE}),
    State.SETTLE: frozenset({State.ACQUIRE}),
    State.ACQUIRE: frozenset({State.STORE}),
    # SETTLE: the next rate step turning in the same pose; ACQUIRE: the next block of a noise record.
    State.STORE: frozenset({State.MOVE, State.RAMP, State.SAFE, State.COOL, State.SETTLE, State.ACQUIRE}),
    State.COOL: frozenset({State.MOVE}),
    State.SAFE: frozenset({State.FIT, State.DONE, State.ABORTED}),
    State.FIT: frozenset({State.DONE}),
    State.ABORTING: frozenset({State.SAFE}),
    State.DONE: frozenset(),
    State.ABORTED: frozenset(),
}
# A fault or a signal may strike in any active state; it always leads through ABORTING to SAFE.
for _state in ACTIVE_STATES:
    TRANSITIONS[_state] = TRANSITIONS[_state] | {State.ABORTING}


#: The event kind the engine logs each move under, its message `transition_text`'s.
TRANSITION_KIND = "transition"


def transition_text(previous: State, target: State, reason: str = "") -> str:
    """How a move reads in the campaign's event log: "safe → fit", with its reason in brackets."""
    return f"{previous} → {target}" + (f" ({reason})" if reason else "")


def entered_at(events: Iterable[StoredEvent], state: State) -> list[str]:
    """The wall-clock times the log says the engine entered `state`, oldest first."""
    return [e.wall_time for e in events
            if e.kind == TRANSITION_KIND and e.message.split(" (")[0].endswith(f"→ {state}")]


class IllegalTransition(RuntimeError):
    """The engine tried a move the table does not allow: a bug, never an instrument fault."""


class StateMachine:
    def __init__(self, on_transition: Callable[[State, State, str], None]) -> None:
        self.state = State.IDLE
        self._on_transition = on_transition

    def go(self, target: State, reason: str = "") -> None:
        if target not in TRANSITIONS[self.state]:
            raise IllegalTransition(f"{self.state} → {target} is not in the transition table")
        previous, self.state = self.state, target
        self._on_transition(previous, target, reason)
