"""Reading every DUT of a pose at once, so they sample the same instants and a pose costs one block's time.

Sensors whose bridges capture blocks by themselves are started together and fetched in rounds by one
thread; any others are read by one thread each on the clock's concurrent runner.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import partial

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import BlockCapturing
from accelcal_rig.instruments.capture import capture_together
from accelcal_rig.instruments.interfaces import SampleBlock, Sensor


def acquire_together(sensors: Sequence[Sensor], n_samples: int, clock: Clock,
                     ranges: Mapping[str, float]) -> list[SampleBlock]:
    """One gap-free block of `n_samples` from each sensor, over the same instants, each checked by the
    data watchdog (a transient failure: the caller's retry takes a new block)."""
    capturing = [sensor for sensor in sensors
                 if 0 < n_samples <= sensor.capture_capacity_samples and isinstance(sensor, BlockCapturing)]
    if len(capturing) == len(sensors):
        blocks = capture_together(capturing, n_samples, clock)
    else:
        blocks = clock.run_concurrently([partial(sensor.acquire, n_samples) for sensor in sensors])
    for sensor, block in zip(sensors, blocks):
        check_block(sensor, block, ranges)
    return blocks


def check_block(sensor: Sensor, block: SampleBlock, ranges: Mapping[str, float]) -> None:
    """Watchdog on the data, each channel of the part: an axis whose every sample is the same code has
    stopped (real noise moves it by many LSB at any data rate), and a code at either end of the ADC range is
    saturated."""
    channels = sensor.part.channels
    for channel in channels:
        if channel.name not in block.codes:
            raise InstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): its block holds no {channel.name} codes "
                                  f"(its driver reads {', '.join(block.codes) or 'none'}; its part has "
                                  f"{', '.join(sensor.part.channel_names)})")
        codes = block.codes[channel.name]
        named = f"{channel.name} axis" if len(channels) > 1 else "axis"
        frozen = [axis for axis, values in zip(channel.axes, codes.T) if values.size > 1 and np.ptp(values) == 0]
        if frozen:
            raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): data stuck: every one of "
                                           f"{len(codes)} samples of {named} {','.join(frozen)} reads the same code")
        if np.any(codes >= channel.code_max) or np.any(codes <= channel.code_min):
            raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): saturated at "
                                           f"±{ranges[channel.name]} {channel.unit} (a code at the end of the ADC range)")
