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
from accelcal_rig.instruments.capabilities import RetriesExchanges
from accelcal_rig.instruments.interfaces import Chamber, Sensor, Turntable
from accelcal_rig.instruments.retrying import RetryingChamber, RetryingSensor, RetryingTurntable

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

    def retried_chamber(self, chamber: Chamber) -> Chamber:
        """The chamber with its wire exchanges retried (see `_retries_its_own`), or a retrying stand-in."""
        return chamber if self._retries_its_own(chamber) else RetryingChamber(chamber, self.call)

    def retried_turntable(self, turntable: Turntable) -> Turntable:
        return turntable if self._retries_its_own(turntable) else RetryingTurntable(turntable, self.call)

    def retried_sensor(self, sensor: Sensor) -> Sensor:
        return sensor if self._retries_its_own(sensor) else RetryingSensor(sensor, self.call)

    def _retries_its_own(self, device: object) -> bool:
        """A driver retries its own exchanges (one request and its reply each, safe to repeat), given this
        retrier's `call`; a device without them (a test double) is retried method by method by a stand-in
        with its capabilities."""
        if isinstance(device, RetriesExchanges):
            device.retry_exchanges(self.call)
            return True
        return False
