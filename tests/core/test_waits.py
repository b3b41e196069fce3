import pytest

from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.core.waits import wait_until
from accelcal_rig.errors import WaitTimeout


def test_returns_the_time_the_condition_first_held() -> None:
    clock = VirtualClock()
    assert wait_until(clock, lambda: clock.now() >= 25, timeout_s=100, poll_s=10, what="x") == 30


def test_deadline_passes_with_the_named_outcome_after_a_final_check() -> None:
    clock = VirtualClock()
    checks = []
    with pytest.raises(WaitTimeout, match="chamber reaching 60 °C: not reached within 0:01:35"):
        wait_until(clock, lambda: checks.append(clock.now()) and False, timeout_s=95, poll_s=10,
                   what="chamber reaching 60 °C")
    assert checks[-1] == 95  # checked once more at the deadline itself, never past it
    assert clock.now() == 95


def test_virtual_clock_refuses_to_go_backwards() -> None:
    with pytest.raises(ValueError):
        VirtualClock().sleep(-1)


def test_concurrent_tasks_share_virtual_time_like_real_parallel_work() -> None:
    clock = VirtualClock()
    seen = []

    def task(step_s: float, steps: int) -> list[float]:
        times = []
        for _ in range(steps):
            clock.sleep(step_s)
            times.append(round(clock.now(), 9))
        seen.append(step_s)
        return times

    results = clock.run_concurrently([lambda: task(0.25, 3), lambda: task(0.1, 5), lambda: task(1.0, 1)])
    assert results == [[0.25, 0.5, 0.75], [0.1, 0.2, 0.3, 0.4, 0.5], [1.0]]
    assert clock.now() == 1.0            # the longest task's time, not the sum (2.25 s)
    clock.sleep(0.5)                     # outside a concurrent section: plain sleeping again
    assert clock.now() == 1.5


def test_a_failing_task_is_raised_after_every_task_has_ended() -> None:
    clock = VirtualClock()
    finished = []

    def fails() -> None:
        clock.sleep(0.1)
        raise OSError("port gone")

    def slow() -> None:
        clock.sleep(5.0)
        finished.append(clock.now())

    with pytest.raises(OSError, match="port gone"):
        clock.run_concurrently([fails, slow])
    assert finished == [5.0]             # no thread left behind, using an instrument


def test_an_interrupt_before_the_tasks_start_leaves_no_thread_waiting(monkeypatch) -> None:
    import threading

    from accelcal_rig.core import clock as clock_module

    class InterruptedInCaller(threading.Barrier):
        def wait(self, timeout=None):
            if threading.current_thread() is threading.main_thread():
                raise KeyboardInterrupt  # Ctrl-C while the caller waits for the tasks to register
            return super().wait(timeout)

    monkeypatch.setattr(clock_module.threading, "Barrier", InterruptedInCaller)
    started = []
    before = threading.active_count()
    with pytest.raises(KeyboardInterrupt):
        VirtualClock().run_concurrently([lambda: started.append(1), lambda: started.append(2)])
    assert started == []                          # no task began after the interrupt
    assert threading.active_count() == before     # and no thread is left blocked
