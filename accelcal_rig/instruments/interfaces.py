"""What the engine needs from each instrument. Simulated and hardware drivers implement the same shapes."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from accelcal_rig.parts.part import Part


@dataclass(frozen=True)
class DeviceIdentity:
    """A DUT's identification registers (those its part names, e.g. DEVID_AD, DEVID_MST, PARTID of an ADXL355;
    WHO_AM_I of an ICM-42688-P) and its silicon revision where it has a register for it (None where not)."""

    registers: tuple[int, ...]
    revision: int | None = None

    def describe(self, label: str) -> str:
        """"ADXL355 rev 1", or "ICM-42688-P" for a part that states no revision."""
        return label if self.revision is None else f"{label} rev {self.revision}"


@dataclass(frozen=True)
class SampleBlock:
    """A gap-free block of raw samples from one DUT, of every channel its part has at the same instants.

    `codes` holds each channel's signed codes by the channel's name, shape (n, axes) (an ADXL355: `accel`,
    20-bit codes on x, y, z); `t_start_s`/`t_end_s` are clock times of the first and last sample;
    `temperature_c` is the DUT's own temperature sensor read before and after the block.
    """

    codes: Mapping[str, np.ndarray]
    t_start_s: float
    t_end_s: float
    temperature_c: tuple[float, float]


@runtime_checkable
class Chamber(Protocol):
    """Thermal chamber controller: what every one has. Setpoint writes are range-checked by the caller and
    read back here. What only some have (an alarm query, their own limits, a purge, humidity, a set point
    resolution) are the small protocols of `capabilities.py`."""

    endpoint: str

    def identify(self) -> str: ...
    def read_temperature_c(self) -> float: ...
    def write_setpoint_c(self, setpoint_c: float) -> None: ...
    def read_setpoint_c(self) -> float: ...
    def set_power(self, on: bool) -> None: ...
    def close(self) -> None: ...


@runtime_checkable
class Positioning(Protocol):
    """Moves to angles (degrees, in the rig config's axis order) and says when it is there: what every
    turntable does (a rate table's constant rate is `capabilities.ConstantRateRotation`)."""

    def move_to(self, angles_deg: np.ndarray) -> None: ...
    def read_angles_deg(self) -> np.ndarray: ...
    def in_position(self) -> bool: ...


@runtime_checkable
class Turntable(Positioning, Protocol):
    """Positioning turntable; angles in degrees in the rig config's axis order."""

    endpoint: str

    def identify(self) -> str: ...
    def stop(self) -> None: ...
    def close(self) -> None: ...


class Sensor(Protocol):
    """One DUT: a digital sensor whose facts (channels, ranges, codes, identity) its `part` gives."""

    serial: str
    endpoint: str
    part: Part

    @property
    def capture_capacity_samples(self) -> int:
        """The largest block its bridge captures by itself (then it is `capabilities.BlockCapturing`); 0: none."""

    def identify(self) -> DeviceIdentity: ...
    def reset(self) -> None: ...
    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        """Each channel's range (± full scale in its unit, by channel name) and the output data rate."""

    def start_measurement(self) -> None: ...
    def standby(self) -> None: ...
    def read_settings(self) -> tuple[dict[str, float], float]:
        """(each channel's range, the output data rate) as the device reports them."""

    def read_temperature_c(self) -> float: ...
    def acquire(self, n_samples: int) -> SampleBlock: ...
    def close(self) -> None: ...


@dataclass
class RigInstruments:
    """Everything the engine drives, plus an optional source of simulation truth for the file."""

    chamber: Chamber
    turntable: Turntable
    sensors: list[Sensor]
    truth: TruthSource | None = None

    def close(self) -> list[str]:
        """Release every connection, each in its own guard; return the failures, one line each."""
        return close_each(self.chamber, self.turntable, self.sensors)


def close_each(chamber: Chamber | None, turntable: Turntable | None, sensors: list[Sensor]) -> list[str]:
    """Close every instrument given, each in its own guard; the failures, one line each naming it."""
    failures = []
    devices: list[tuple[str, Chamber | Turntable | Sensor]] = [
        *((("chamber", chamber),) if chamber is not None else ()),
        *((("turntable", turntable),) if turntable is not None else ()),
        *((f"sensor {s.serial}", s) for s in sensors)]
    for name, device in devices:
        try:
            device.close()
        except Exception as exc:  # noqa: BLE001 - one stuck port must not keep the others open
            failures.append(f"{name} ({device.endpoint}): close failed: {exc}")
    return failures


class TruthSource(Protocol):
    """Only a simulated rig has one: the hidden parameters behind the samples of a block."""

    def describe(self, serial: str, odr_hz: float) -> dict[str, np.ndarray | str | float]: ...
    def block_truth(self, serial: str, block: SampleBlock) -> dict[str, np.ndarray]: ...
