"""Reading every DUT of a pose at once, so they sample the same instants and a pose costs one block's time.

Sensors whose bridges capture blocks by themselves are started together and fetched in rounds by one
thread; any others are read by one thread each on the clock's concurrent runner.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

from accelcal_rig.engine.clock import Clock
import numpy as np

from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_transport import CaptureOverflow
from accelcal_rig.instruments.interfaces import Accelerometer, BlockCapturing, SampleBlock

#: Attempts at a gap-free block before lost samples are reported as a fault.
OVERFLOW_ATTEMPTS = 3


def acquire_together(sensors: Sequence[Accelerometer], n_samples: int, clock: Clock,
                     range_g: int) -> list[SampleBlock]:
    """One gap-free block of `n_samples` from each sensor, over the same instants, each checked by the
    data watchdog (a transient failure: the caller's retry takes a new block)."""
    if all(0 < n_samples <= sensor.capture_capacity_samples for sensor in sensors):
        blocks = capture_together(sensors, n_samples, clock)  # type: ignore[arg-type]
    else:
        blocks = clock.run_concurrently([partial(sensor.acquire, n_samples) for sensor in sensors])
    for sensor, block in zip(sensors, blocks):
        check_block(sensor, block, range_g)
    return blocks


def check_block(sensor: Accelerometer, block: SampleBlock, range_g: int) -> None:
    """Watchdog on the data: an axis whose every sample is the same code has stopped (real noise moves
    it by many LSB at any data rate), and a code at either end of the ADC range is saturated."""
    codes = block.codes_xyz
    frozen = [axis for axis, values in zip("xyz", codes.T) if values.size > 1 and np.ptp(values) == 0]
    if frozen:
        raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): data stuck: every one of "
                                       f"{len(codes)} samples of axis {','.join(frozen)} reads the same code")
    if np.any(codes >= adxl355.CODE_MAX) or np.any(codes <= adxl355.CODE_MIN):
        raise TransientInstrumentError(f"sensor {sensor.serial} ({sensor.endpoint}): saturated at ±{range_g} g "
                                       "(a code at the end of the ADC range)")


def capture_together(sensors: Sequence[BlockCapturing], n_samples: int, clock: Clock) -> list[SampleBlock]:
    """Start every capture, then fetch in rounds until all are complete. A capture that lost samples is
    started again (that sensor only), OVERFLOW_ATTEMPTS times at most."""
    blocks: dict[int, SampleBlock] = {}
    pending = list(range(len(sensors)))
    for _ in range(OVERFLOW_ATTEMPTS):
        for index in pending:
            sensors[index].begin_capture(n_samples)
        capturing, overflowed = list(pending), []
        while capturing:
            clock.sleep(min(sensors[index].capture_wait_s() for index in capturing))
            for index in list(capturing):
                try:
                    complete = sensors[index].fetch_capture()
                except CaptureOverflow:
                    capturing.remove(index)
                    overflowed.append(index)
                    continue
                if complete:
                    capturing.remove(index)
                    blocks[index] = sensors[index].end_capture()
        pending = overflowed
        if not pending:
            return [blocks[index] for index in range(len(sensors))]
    lost = sensors[pending[0]]
    raise InstrumentError(f"sensor {lost.serial} ({lost.endpoint}): FIFO overflowed in {OVERFLOW_ATTEMPTS} "
                          "attempts: the bridge's capture lost samples")
