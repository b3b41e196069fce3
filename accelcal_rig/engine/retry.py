"""Retries of transient instrument failures: bounded exponential backoff on the campaign's clock, every
retry in the event log with the instrument and the error, and a reconnect when the link itself failed.

A failure that outlasts its retries becomes a plain InstrumentError, so no outer layer retries it again.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from accelcal_rig.config.rig import RetryPolicy
from accelcal_rig.engine.clock import Clock
from accelcal_rig.engine.events import EventLog
from accelcal_rig.errors import InstrumentError, TransientInstrumentError

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

    def wrap(self, device: T) -> T:
        """The device with every method retried (each must be safe to repeat)."""
        return _RetryingInstrument(device, self)  # type: ignore[return-value]


class _RetryingInstrument:
    """Stands in for an instrument: attributes pass through, method calls go through the Retrier."""

    def __init__(self, device: Any, retrier: Retrier) -> None:
        self._device = device
        self._retrier = retrier
        self._not_retried = frozenset({"close", "reconnect"})

    def __getattr__(self, name: str) -> Any:
        attribute = getattr(self._device, name)
        if not callable(attribute) or name.startswith("_") or name in self._not_retried:
            return attribute
        reconnect = getattr(self._device, "reconnect", None)

        def retried(*args: Any, **kwargs: Any) -> Any:
            return self._retrier.call(lambda: attribute(*args, **kwargs), reconnect)

        return retried
