"""A block of consecutive samples read from a part's data registers at its output data rate on the injected
clock, one burst per sample, each burst's status saying whether its sample is new: how a host without the
part's FIFO (or a bridge without block capture) takes a block. Shared by the register-level drivers that poll
(the ICM-42688-P's, the LIS3MDL's)."""

from __future__ import annotations

from collections.abc import Callable

from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError

#: A sample read later than this many sample periods after the previous one may have missed one between.
LATE_PERIODS = 1.5
#: Reads of a sample that its status says is not new yet, per sample, before giving up on the part.
STALE_READS = 16
#: Blocks started again after a late read before the link is declared too slow for the rate.
LATE_ATTEMPTS = 3

#: One burst: (the sample's bytes, whether the part's status says it is new; the read clears that).
SampleRead = Callable[[], tuple[bytes, bool]]


def poll_block(clock: Clock, odr_hz: float, n_samples: int, read_sample: SampleRead,
               fault: Callable[[str], InstrumentError]) -> tuple[bytes, float]:
    """`n_samples` consecutive new samples, back to back, and the time of the first; a block with a late read
    (a sample may have gone by unread) is started again, LATE_ATTEMPTS times at most. `fault` makes the part's
    one-line error."""
    for _ in range(LATE_ATTEMPTS):
        block = _try_block(clock, odr_hz, n_samples, read_sample, fault)
        if block is not None:
            return block
    raise fault(f"reads came later than {LATE_PERIODS:g} sample periods in {LATE_ATTEMPTS} attempts: the link "
                f"cannot poll {odr_hz:g} Hz")


def _try_block(clock: Clock, odr_hz: float, n_samples: int, read_sample: SampleRead,
               fault: Callable[[str], InstrumentError]) -> tuple[bytes, float] | None:
    period = 1.0 / odr_hz
    read_sample()  # clears the status: the next sample counted is one that arrives from now on
    raw = bytearray()
    t_start = previous = clock.now()
    for index in range(n_samples):
        # Paced from the block's first read, not from the last one: each read's round trip would otherwise
        # push the next a little later, until a sample went by unread.
        due = t_start + index * period if index else previous + period
        clock.sleep(max(0.0, due - clock.now()))
        sample = _fresh_sample(clock, period, read_sample, fault)
        now = clock.now()
        if now - previous > LATE_PERIODS * period:
            return None
        if index == 0:
            t_start = now
        previous = now
        raw += sample
    return bytes(raw), t_start


def _fresh_sample(clock: Clock, period: float, read_sample: SampleRead,
                  fault: Callable[[str], InstrumentError]) -> bytes:
    """The next sample its status says is new, re-read an eighth of a period later while it is not."""
    for _ in range(STALE_READS):
        sample, new = read_sample()
        if new:
            return sample
        clock.sleep(period / 8)
    raise fault(f"no new sample in {STALE_READS} reads (its data-ready status never set): is it measuring?")
