"""Retries: bounded exponential backoff on the campaign clock, logged, reconnecting a failed link."""

from __future__ import annotations

import pytest

from accelcal_rig.config.rig import RetryPolicy
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.errors import InstrumentError, TransientInstrumentError


class RecordingEvents:
    def __init__(self) -> None:
        self.warnings: list[str] = []

    def warning(self, kind: str, message: str) -> None:
        assert kind == "retry"
        self.warnings.append(message)


class FlakyChamber:
    """Its temperature read fails `failures` times, the first one with a link error, then answers; it can
    reconnect, and refuses any power command."""

    endpoint = "serial /dev/ttyUSB0"

    def __init__(self, failures: int) -> None:
        self.failures = failures
        self.calls = 0
        self.reconnects = 0

    def identify(self) -> str:
        return "flaky"

    def read_temperature_c(self) -> float:
        self.calls += 1
        if self.calls <= self.failures:
            raise TransientInstrumentError(f"device ({self.endpoint}): no reply", reconnect=self.calls == 1)
        return 21.0

    def write_setpoint_c(self, setpoint_c: float) -> None: ...

    def read_setpoint_c(self) -> float:
        return 20.0

    def set_power(self, on: bool) -> None:
        self.calls += 1
        raise InstrumentError("device: command refused")

    def close(self) -> None: ...

    def reconnect(self) -> None:
        self.reconnects += 1


def retrier(attempts: int = 5) -> tuple[Retrier, VirtualClock, RecordingEvents]:
    clock, events = VirtualClock(), RecordingEvents()
    return Retrier(RetryPolicy(attempts=attempts, first_backoff_s=0.5, max_backoff_s=2.0), clock, events), clock, events  # type: ignore[arg-type]


def test_transient_failures_are_retried_with_doubling_capped_backoff() -> None:
    retry, clock, events = retrier()
    inner = FlakyChamber(failures=4)
    device = retry.retried_chamber(inner)
    assert device.read_temperature_c() == 21.0
    assert inner.calls == 5 and inner.reconnects == 1
    assert clock.now() == pytest.approx(0.5 + 1.0 + 2.0 + 2.0)  # capped at max_backoff_s
    assert events.warnings[0] == "device (serial /dev/ttyUSB0): no reply; attempt 2 of 5 in 0.5 s after reconnecting"
    assert [w.split("; ")[1] for w in events.warnings[1:]] == ["attempt 3 of 5 in 1 s", "attempt 4 of 5 in 2 s",
                                                               "attempt 5 of 5 in 2 s"]


def test_a_failure_that_outlasts_its_retries_is_a_plain_fault() -> None:
    retry, _, events = retrier(attempts=3)
    inner = FlakyChamber(failures=10)
    device = retry.retried_chamber(inner)
    with pytest.raises(InstrumentError, match=r"no reply \(still failing after 3 attempts\)") as raised:
        device.read_temperature_c()
    assert not isinstance(raised.value, TransientInstrumentError)  # an outer retry does not retry it again
    assert inner.calls == 3 and len(events.warnings) == 2


def test_refusals_are_not_retried_and_attributes_pass_through() -> None:
    retry, clock, events = retrier()
    inner = FlakyChamber(failures=0)
    device = retry.retried_chamber(inner)
    with pytest.raises(InstrumentError, match="command refused"):
        device.set_power(True)
    assert inner.calls == 1 and clock.now() == 0.0 and events.warnings == []
    assert device.endpoint == "serial /dev/ttyUSB0"
