"""Retries of transient instrument failures: bounded exponential backoff on the campaign's clock, every
retry in the event log with the instrument and the error, and a reconnect when the link itself failed.

A failure that outlasts its retries becomes a plain InstrumentError, so no outer layer retries it again.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from accelcal_rig.config.rig import RetryPolicy
from accelcal_rig.core.clock import Clock
from accelcal_rig.engine.events import EventLog
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.retrying import Retrying

T = TypeVar("T")


class Retrier:
    def __init__(self, policy: RetryPolicy, clock: Clock, events: EventLog) -> None:
        self.policy = policy
        self._clock = clock
        self._events = events

    def call(self, operation: Callable[[], T], reconnect: Callable[[], None] | None = None) -> T:
        """`operation()`, tried up to `policy.attempts` times while it fails transiently."""
        policy = self.policy
        for attempt in range(1, policy.attempts + 1):
            try:
                return operation()
            except TransientInstrumentError as exc:
                if attempt == policy.attempts:
                    raise InstrumentError(f"{exc} (still failing after {attempt} attempts)") from exc
                backoff_s = min(policy.max_backoff_s, policy.first_backoff_s * 2 ** (attempt - 1))
                self._events.warning("retry", f"{exc}; attempt {attempt + 1} of {policy.attempts} in {backoff_s:g} s"
                                              f"{' after reconnecting' if exc.reconnect and reconnect else ''}")
                self._clock.sleep(backoff_s)
                if exc.reconnect and reconnect is not None:
                    try:
                        reconnect()
                    except InstrumentError as failed:  # still gone: the next attempt fails and waits longer
                        self._events.warning("retry", f"reconnect failed: {failed}")
        raise AssertionError("unreachable")

    def retried(self, device: T) -> T:
        """The device with its wire exchanges retried: a driver retries its own exchanges (one request and
        its reply each, safe to repeat); a device without them (a test double) is retried method by method."""
        if hasattr(device, "retry_exchanges"):
            device.retry_exchanges(self.call)  # type: ignore[attr-defined]
            return device
        return Retrying(device, self.call)  # type: ignore[return-value]
