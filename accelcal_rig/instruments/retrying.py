"""Instruments and transports whose every call goes through a retry function (see engine/retry.py): typed
delegates with the capabilities of what they wrap and no others.

Drivers use `RetryingTransport` on their transports, where each method is one exchange on the wire and safe
to repeat; a test double without a transport of its own is wrapped whole (`RetryingChamber`, …).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Self, TypeVar, cast

from accelcal_rig.instruments.adxl355_transport import BlockCapture, RegisterTransport
from accelcal_rig.instruments.capabilities import Reconnecting, RetryCall
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.delegates import ChamberDelegate, TurntableDelegate
from accelcal_rig.instruments.interfaces import Chamber, Sensor, Turntable
from accelcal_rig.instruments.sensor_delegate import SensorDelegate

__all__ = ["RetryCall", "RetryingSensor", "RetryingChamber", "RetryingTransport", "RetryingTurntable"]

T = TypeVar("T")


def _reconnect_of(device: object) -> Callable[[], None] | None:
    """How a retry opens the device's link again, where it can."""
    return device.reconnect if isinstance(device, Reconnecting) else None


class RetryingChamber(ChamberDelegate):
    def __init__(self, chamber: Chamber, call: RetryCall) -> None:
        super().__init__(chamber)
        self._call, self._reconnect = call, _reconnect_of(chamber)

    def _through(self, operation: Callable[[], T]) -> T:
        return self._call(operation, self._reconnect)


class RetryingTurntable(TurntableDelegate):
    def __init__(self, turntable: Turntable, call: RetryCall) -> None:
        super().__init__(turntable)
        self._call, self._reconnect = call, _reconnect_of(turntable)

    def _through(self, operation: Callable[[], T]) -> T:
        return self._call(operation, self._reconnect)


class RetryingSensor(SensorDelegate):
    def __init__(self, sensor: Sensor, call: RetryCall) -> None:
        super().__init__(sensor)
        self._call, self._reconnect = call, _reconnect_of(sensor)

    def _through(self, operation: Callable[[], T]) -> T:
        return self._call(operation, self._reconnect)


class RetryingTransport:
    """A register transport whose reads, writes and (where it has them) captures are each retried; a
    request posted now and received later is not, so those stay with the bare transport."""

    def __new__(cls, transport: RegisterTransport, call: RetryCall) -> Self:
        mixins = {BlockCapture: _RetriedCapture, Reconnecting: _TransportReconnect}
        chosen = [mixin for capability, mixin in mixins.items() if isinstance(transport, capability)]
        return instance_of(composed(cls, chosen if cls is RetryingTransport else []))

    def __init__(self, transport: RegisterTransport, call: RetryCall) -> None:
        self._transport = transport
        self._call, self._reconnect = call, _reconnect_of(transport)
        self.endpoint = transport.endpoint

    @property
    def capture_capacity_samples(self) -> int:
        return self._transport.capture_capacity_samples

    def _through(self, operation: Callable[[], T]) -> T:
        return self._call(operation, self._reconnect)

    def read(self, address: int, count: int) -> bytes:
        return self._through(lambda: self._transport.read(address, count))

    def write(self, address: int, value: int) -> None:
        self._through(lambda: self._transport.write(address, value))

    def close(self) -> None:
        self._transport.close()


class _RetriedCapture(RetryingTransport):
    def start_capture(self, n_samples: int) -> int:
        return self._through(lambda: cast(BlockCapture, self._transport).start_capture(n_samples))

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        return self._through(lambda: cast(BlockCapture, self._transport).fetch_capture(first))


class _TransportReconnect(RetryingTransport):
    def reconnect(self) -> None:
        cast(Reconnecting, self._transport).reconnect()
