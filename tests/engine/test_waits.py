import pytest

from accelcal_rig.engine.clock import VirtualClock
from accelcal_rig.engine.waits import wait_until
from accelcal_rig.errors import WaitTimeout


def test_returns_the_time_the_condition_first_held() -> None:
    clock = VirtualClock()
    assert wait_until(clock, lambda: clock.now() >= 25, timeout_s=100, poll_s=10, what="x") == 30


def test_deadline_passes_with_the_named_outcome_after_a_final_check() -> None:
    clock = VirtualClock()
    checks = []
    with pytest.raises(WaitTimeout, match="chamber reaching 60 °C: not reached within 95 s"):
        wait_until(clock, lambda: checks.append(clock.now()) and False, timeout_s=95, poll_s=10,
                   what="chamber reaching 60 °C")
    assert checks[-1] == 95  # checked once more at the deadline itself, never past it
    assert clock.now() == 95


def test_virtual_clock_refuses_to_go_backwards() -> None:
    with pytest.raises(ValueError):
        VirtualClock().sleep(-1)
