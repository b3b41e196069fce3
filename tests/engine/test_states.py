import pytest

from accelcal_rig.engine.states import ACTIVE_STATES, TRANSITIONS, IllegalTransition, State, StateMachine


def test_every_active_state_can_abort_and_aborting_leads_to_safe() -> None:
    for state in ACTIVE_STATES:
        assert State.ABORTING in TRANSITIONS[state]
    assert TRANSITIONS[State.ABORTING] == {State.SAFE}
    assert TRANSITIONS[State.DONE] == TRANSITIONS[State.ABORTED] == frozenset()


def test_every_state_is_reachable_from_idle() -> None:
    seen, frontier = {State.IDLE}, [State.IDLE]
    while frontier:
        for target in TRANSITIONS[frontier.pop()]:
            if target not in seen:
                seen.add(target)
                frontier.append(target)
    assert seen == set(State)


def test_illegal_transition_is_refused_and_legal_ones_are_reported() -> None:
    moves = []
    machine = StateMachine(lambda a, b, why: moves.append((a, b, why)))
    machine.go(State.PREFLIGHT, "start")
    with pytest.raises(IllegalTransition, match="preflight → acquire"):
        machine.go(State.ACQUIRE)
    assert machine.state is State.PREFLIGHT
    assert moves == [(State.IDLE, State.PREFLIGHT, "start")]
