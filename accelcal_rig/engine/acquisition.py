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
from accelcal_rig.parts.part import Channel


def acquire_together(sensors: Sequence[Sensor], n_samples: int, clock: Clock,
                     ranges: Mapping[str, float], may_saturate: frozenset[str] = frozenset()) -> list[SampleBlock]:
    """One gap-free block of `n_samples` from each sensor, over the same instants, each checked by the
    data watchdog (a transient failure: the caller's retry takes a new block); the channels named in
    `may_saturate` are not judged saturated (an accelerometer on a turning table: no fit uses it there)."""
    capturing = [sensor for sensor in sensors
                 if 0 < n_samples <= sensor.capture_capacity_samples and isinstance(sensor, BlockCapturing)]
    if len(capturing) == len(sensors):
        blocks = capture_together(capturing, n_samples, clock)
    else:
        blocks = clock.run_concurrently([partial(sensor.acquire, n_samples) for sensor in sensors])
    for sensor, block in zip(sensors, blocks):
        check_block(sensor, block, ranges, may_saturate)
    return blocks


def check_block(sensor: Sensor, block: SampleBlock, ranges: Mapping[str, float],
                may_saturate: frozenset[str] = frozenset()) -> None:
    """Watchdog on the data, each channel of the part: an axis whose every sample is the same code has
    stopped where the part's noise moves it by a code or more; a channel whose noise is finer than its code
    (an ICM-42688-P's gyroscope at ±2000 °/s: 0.3 code) holds one code for a whole block now and then, so
    there only every axis frozen at once is a stopped sensor; a code at either end of the ADC range is
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
        if frozen and (len(frozen) == len(channel.axes) or _noise_codes(channel, block, ranges[channel.name]) >= 1.0):
            raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): data stuck: every one of "
                                           f"{len(codes)} samples of {named} {','.join(frozen)} reads the same code")
        if channel.name not in may_saturate and (np.any(codes >= channel.code_max) or np.any(codes <= channel.code_min)):
            raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): saturated at "
                                           f"±{ranges[channel.name]} {channel.unit} (a code at the end of the ADC range)")


def _noise_codes(channel: Channel, block: SampleBlock, range_: float) -> float:
    """The channel's per-sample noise in codes at the block's data rate: its density over the bandwidth of an
    ODR/4 low-pass (×π/2), over its code at the range."""
    n = max(len(block.codes[channel.name]) - 1, 1)
    span_s = block.t_end_s - block.t_start_s
    rate_hz = n / span_s if span_s > 0 else 1.0
    return 1e-6 * channel.noise_density_micro_per_rthz * float(np.sqrt(np.pi / 2 * rate_hz / 4)) / channel.lsb(range_)
