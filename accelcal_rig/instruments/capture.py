"""Block captures by the sensor bridges themselves: started together, fetched in rounds by one thread, each
round's requests sent to every bridge before any reply is read."""

from __future__ import annotations

from collections.abc import Sequence

from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.adxl355_transport import CaptureOverflow
from accelcal_rig.instruments.capabilities import BlockCapturing
from accelcal_rig.instruments.interfaces import SampleBlock

#: Attempts at a gap-free block before lost samples are reported as a fault.
OVERFLOW_ATTEMPTS = 3


def capture_together(sensors: Sequence[BlockCapturing], n_samples: int, clock: Clock) -> list[SampleBlock]:
    """Start every capture, then fetch in rounds until all are complete. A capture that lost samples is
    started again (that sensor only), OVERFLOW_ATTEMPTS times at most. A capture whose start had to be
    retried begins later than the others: each block is timed from its own start."""
    blocks: dict[int, SampleBlock] = {}
    pending = list(range(len(sensors)))
    for _ in range(OVERFLOW_ATTEMPTS):
        posted = [sensors[index].post_capture(n_samples) for index in pending]  # every bridge asked first,
        for index, sent in zip(pending, posted):  # then every reply read: they answer at the same time
            sensors[index].begin_capture(n_samples, sent)
        capturing, overflowed = list(pending), []
        while capturing:
            clock.sleep(min(sensors[index].capture_wait_s() for index in capturing))
            posted = [sensors[index].post_fetch() for index in capturing]
            for index, sent in zip(list(capturing), posted):
                try:
                    complete = sensors[index].fetch_capture(sent)
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
