"""A typed stand-in for a DUT (see delegates.py): the Sensor members passed on through `_through`,
and block capture, posted temperature reads and reconnecting only where the DUT has them."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Self, TypeVar, cast

from accelcal_rig.instruments.capabilities import BlockCapturing, Reconnecting, TemperaturePosting
from accelcal_rig.instruments.composition import composed, instance_of
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock, Sensor

T = TypeVar("T")


class SensorDelegate:
    """Stands in for `sensor`: the core members passed on, each capability only where it has one."""

    _passes_on: ClassVar[Mapping[type, type[SensorDelegate]]] = {}

    def __new__(cls, sensor: Sensor, *args: Any, **kwargs: Any) -> Self:
        mixins = [mixin for capability, mixin in cls._passes_on.items() if isinstance(sensor, capability)]
        return instance_of(composed(cls, mixins))

    def __init__(self, sensor: Sensor) -> None:
        self._sensor = sensor
        self.serial = sensor.serial
        self.endpoint = sensor.endpoint
        self.part = sensor.part

    def _through(self, operation: Callable[[], T]) -> T:
        """Run one call on the DUT (a subclass retries it)."""
        return operation()

    @property
    def capture_capacity_samples(self) -> int:
        return self._sensor.capture_capacity_samples

    def identify(self) -> DeviceIdentity:
        return self._through(self._sensor.identify)

    def reset(self) -> None:
        self._through(self._sensor.reset)

    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        self._through(lambda: self._sensor.configure(ranges, odr_hz))

    def start_measurement(self) -> None:
        self._through(self._sensor.start_measurement)

    def standby(self) -> None:
        self._through(self._sensor.standby)

    def read_settings(self) -> tuple[dict[str, float], float]:
        return self._through(self._sensor.read_settings)

    def read_temperature_c(self) -> float:
        return self._through(self._sensor.read_temperature_c)

    def acquire(self, n_samples: int) -> SampleBlock:
        return self._through(lambda: self._sensor.acquire(n_samples))

    def close(self) -> None:
        self._sensor.close()


# Each mixin is composed in only where the DUT has the capability: the casts say what was checked.
class PassBlockCapture(SensorDelegate):
    def _capturing(self) -> BlockCapturing:
        return cast(BlockCapturing, self._sensor)

    def post_capture(self, n_samples: int) -> bool:
        return self._through(lambda: self._capturing().post_capture(n_samples))

    def begin_capture(self, n_samples: int, posted: bool = False) -> None:
        self._through(lambda: self._capturing().begin_capture(n_samples, posted))

    def capture_wait_s(self) -> float:
        return self._through(self._capturing().capture_wait_s)

    def post_fetch(self) -> bool:
        return self._through(self._capturing().post_fetch)

    def fetch_capture(self, posted: bool = False) -> bool:
        return self._through(lambda: self._capturing().fetch_capture(posted))

    def end_capture(self) -> SampleBlock:
        return self._through(self._capturing().end_capture)


class PassTemperaturePosting(SensorDelegate):
    def begin_temperature_read(self) -> bool:
        return self._through(cast(TemperaturePosting, self._sensor).begin_temperature_read)

    def end_temperature_read(self) -> float | None:
        return self._through(cast(TemperaturePosting, self._sensor).end_temperature_read)


class PassSensorReconnect(SensorDelegate):
    def reconnect(self) -> None:
        cast(Reconnecting, self._sensor).reconnect()


#: Every DUT capability a delegate passes on, and how.
SENSOR_CAPABILITIES: Mapping[type, type[SensorDelegate]] = {
    BlockCapturing: PassBlockCapture, TemperaturePosting: PassTemperaturePosting, Reconnecting: PassSensorReconnect}
SensorDelegate._passes_on = SENSOR_CAPABILITIES
