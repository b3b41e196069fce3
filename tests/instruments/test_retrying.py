"""The retry stand-ins of a DUT and of a register transport: typed, with the capabilities of what they wrap
(block capture, posted temperature reads, reconnecting) and no others."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.config.rig import RetryPolicy
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.errors import TransientInstrumentError
from accelcal_rig.instruments.adxl355_transport import BlockCapture
from accelcal_rig.instruments.capabilities import BlockCapturing, Reconnecting, TemperaturePosting
from accelcal_rig.instruments.interfaces import DeviceIdentity, SampleBlock
from accelcal_rig.instruments.retrying import RetryingSensor, RetryingTransport
from accelcal_rig.instruments.temperatures import read_temperatures_together
from accelcal_rig.parts.adxl35x import ADXL355


class Events:
    def warning(self, kind: str, message: str) -> None: ...


def call():
    return Retrier(RetryPolicy(attempts=3, first_backoff_s=0.5, max_backoff_s=2.0), VirtualClock(), Events()).call


class CoreSensor:
    serial, endpoint, part = "SN-1", "test-bridge", ADXL355
    capture_capacity_samples = 0

    def __init__(self) -> None:
        self.temperature_reads = 0

    def identify(self) -> DeviceIdentity:
        return DeviceIdentity((0xAD, 0x1D, 0xED), 1)

    def reset(self) -> None: ...
    def configure(self, range_g: int, odr_hz: float) -> None: ...
    def start_measurement(self) -> None: ...
    def standby(self) -> None: ...

    def read_settings(self) -> tuple[int, float]:
        return 2, 125.0

    def read_temperature_c(self) -> float:
        self.temperature_reads += 1
        return 25.0

    def acquire(self, n_samples: int) -> SampleBlock:
        return SampleBlock({"accel": np.zeros((n_samples, 3), dtype=np.int32)}, 0.0, 1.0, (25.0, 25.0))

    def close(self) -> None: ...


class PostingSensor(CoreSensor):
    def __init__(self) -> None:
        super().__init__()
        self.begun = 0

    def begin_temperature_read(self) -> bool:
        self.begun += 1
        return True

    def end_temperature_read(self) -> float | None:
        return 24.0


class CapturingSensor(CoreSensor):
    def post_capture(self, n_samples: int) -> bool: return False
    def begin_capture(self, n_samples: int, posted: bool = False) -> None: ...
    def capture_wait_s(self) -> float: return 0.0
    def post_fetch(self) -> bool: return False
    def fetch_capture(self, posted: bool = False) -> bool: return True
    def end_capture(self) -> SampleBlock: return self.acquire(1)


@pytest.mark.parametrize("inner_type", [CoreSensor, PostingSensor, CapturingSensor])
def test_a_retrying_sensor_has_a_capability_exactly_when_its_sensor_has_it(inner_type) -> None:
    inner = inner_type()
    wrapper = RetryingSensor(inner, call())
    for capability in (BlockCapturing, TemperaturePosting, Reconnecting):
        assert isinstance(wrapper, capability) == isinstance(inner, capability), capability
    assert isinstance(wrapper, BlockCapturing) == (inner_type is CapturingSensor)
    assert wrapper.serial == "SN-1" and wrapper.part is ADXL355 and wrapper.identify().revision == 1


def test_temperatures_are_posted_through_the_wrapper_where_the_sensor_posts_them() -> None:
    posting, plain = PostingSensor(), CoreSensor()
    wrapped = [RetryingSensor(posting, call()), RetryingSensor(plain, call())]
    assert read_temperatures_together(wrapped).tolist() == [24.0, 25.0]
    assert posting.begun == 1 and posting.temperature_reads == 0 and plain.temperature_reads == 1


class CoreTransport:
    endpoint = "memory"
    capture_capacity_samples = 0

    def __init__(self) -> None:
        self.reads = 0

    def read(self, address: int, count: int) -> bytes:
        self.reads += 1
        if self.reads == 1:
            raise TransientInstrumentError("sensor bridge (memory): garbled reply")
        return bytes(count)

    def write(self, address: int, value: int) -> None: ...
    def close(self) -> None: ...


class CapturingTransport(CoreTransport):
    capture_capacity_samples = 4096

    def start_capture(self, n_samples: int) -> int:
        return 1885

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        return b"", 1885

    def reconnect(self) -> None: ...


@pytest.mark.parametrize("inner_type", [CoreTransport, CapturingTransport])
def test_a_retrying_transport_captures_exactly_when_its_transport_does(inner_type) -> None:
    inner = inner_type()
    bus = RetryingTransport(inner, call())
    assert isinstance(bus, BlockCapture) == (inner_type is CapturingTransport)
    assert isinstance(bus, Reconnecting) == (inner_type is CapturingTransport)
    assert bus.capture_capacity_samples == inner.capture_capacity_samples
    assert bus.read(0x00, 4) == bytes(4) and inner.reads == 2  # the garbled reply asked again
