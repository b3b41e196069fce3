"""A block from a part's FIFO, for any register-level driver whose part has one (the ADXL355's, the
ICM-42688-P's): captured by the serial bridge itself (`C`, then `G` by index until complete) where the block fits
its buffer, else read by the host, the driver's own way; a block that lost samples is taken again. The driver
says how its part's FIFO bytes decode and how the host reads its FIFO; starting, fetching, retrying a lost reply,
retaking a lossy block and timing the block are the same for every part. Several DUTs are started together and
fetched in rounds by one thread (`instruments/capture.py`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np

from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.adxl355_transport import BlockCapture, PostedRequests, RegisterTransport
from accelcal_rig.instruments.capture import OVERFLOW_ATTEMPTS, capture_together
from accelcal_rig.instruments.interfaces import SampleBlock
from accelcal_rig.parts.part import Part

T = TypeVar("T")
#: Channel codes decoded from FIFO bytes, and the bytes of an incomplete trailing sample to carry.
Decoded = tuple[dict[str, np.ndarray], bytes]


@dataclass
class _Capture:
    """A block being captured by the bridge: what is known so far."""

    n_samples: int
    t_start_s: float
    temperature_before_c: float
    pieces: list[dict[str, np.ndarray]] = field(default_factory=list)
    have: int = 0
    carried: bytes = b""
    temperature_after_c: float | None = None


class BridgeCapturing:
    """A driver's blocks from its part's FIFO and its `BlockCapturing` side: its subclass sets `part`, `serial`,
    `endpoint`, `_bus` (the retried transport), `_poster` (the bare one where it posts requests), `_clock`,
    `_odr_hz` and `fifo_loss` (how its part says a sample was lost), decodes its FIFO bytes in `_decode_fifo` and
    reads a block itself in `_try_drain` (None: it lost samples)."""

    part: Part
    serial: str
    endpoint: str
    _bus: RegisterTransport
    _poster: PostedRequests | None
    _clock: Clock
    _odr_hz: float
    #: What the part's FIFO says when it lost samples, as the fault after the last attempt names it.
    fifo_loss = "FIFO overflowed"
    _capture: _Capture | None = None
    #: Clock time the last capture request was posted: when the bridge started it, however much later its reply
    #: is read (after another DUT's retries, say).
    _capture_posted_s: float | None = None

    def _decode_fifo(self, raw: bytes, carried: bytes) -> Decoded:
        raise NotImplementedError

    def _try_drain(self, n_samples: int) -> SampleBlock | None:
        raise NotImplementedError

    def acquire(self, n_samples: int) -> SampleBlock:
        """`n_samples` consecutive samples, captured by the bridge where it can, else read from the FIFO by the
        host; a block that lost samples is taken again, OVERFLOW_ATTEMPTS times at most, then is a fault."""
        if 0 < n_samples <= self.capture_capacity_samples:
            return capture_together([self], n_samples, self._clock)[0]
        for _ in range(OVERFLOW_ATTEMPTS):
            block = self._try_drain(n_samples)
            if block is not None:
                return block
        raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {self.fifo_loss} in {OVERFLOW_ATTEMPTS} "
                              f"attempts: the link cannot keep up with {self._odr_hz:g} Hz")

    @property
    def capture_capacity_samples(self) -> int:
        """The largest block the bridge captures itself (0: none; the host reads the FIFO itself)."""
        return self._bus.capture_capacity_samples

    def post_capture(self, n_samples: int) -> bool:
        """Send the capture request without waiting for its reply (False: not sent; `begin_capture` asks)."""
        self._capture_posted_s = self._clock.now()
        return self._posted(lambda bridge: bridge.post_capture(n_samples))

    def begin_capture(self, n_samples: int, posted: bool = False) -> None:
        """The bridge starts capturing the next `n_samples` (and says the temperature then). `posted`: the
        request went out with `post_capture`; its reply is read here, or the request retried if it failed.
        The block starts when the bridge heard the request that started it, not when its reply was read:
        the replies of posted requests are read one DUT after another, after any retries of those before."""
        raw = self._received(posted, lambda bridge: bridge.receive_capture(n_samples))
        if raw is not None and self._capture_posted_s is not None:
            started_s = self._capture_posted_s
        else:  # not posted, or its reply lost: a capture started again now, by the retried request
            raw = self._capturing_bus().start_capture(n_samples)
            started_s = self._clock.now()
        self._capture_posted_s = None
        self._capture = _Capture(n_samples, started_s, float(self.part.temperature.celsius(raw)))

    def capture_wait_s(self) -> float:
        """Clock time until the rest of the block has been captured."""
        assert self._capture is not None
        return (self._capture.n_samples - self._capture.have) / self._odr_hz

    def post_fetch(self) -> bool:
        """Send the next fetch without waiting for its reply (False: not sent; `fetch_capture` asks)."""
        assert self._capture is not None
        have = self._capture.have
        return self._posted(lambda bridge: bridge.post_fetch(have))

    def fetch_capture(self, posted: bool = False) -> bool:
        """Fetch what the bridge has captured since the last fetch (asked for by index, so a retry after
        a lost reply loses nothing); True once the block is complete. A capture that lost samples raises
        CaptureOverflow; one that stalls past its deadline is a fault. `posted`: as for `begin_capture`."""
        capture = self._capture
        assert capture is not None
        fetched = self._received(posted, lambda bridge: bridge.receive_fetch(capture.have))
        raw, temperature_raw = fetched if fetched is not None else self._capturing_bus().fetch_capture(capture.have)
        codes, capture.carried = self._decode_fifo(raw, capture.carried)
        capture.pieces.append(codes)
        capture.have += len(next(iter(codes.values())))
        if temperature_raw is not None:
            capture.temperature_after_c = float(self.part.temperature.celsius(temperature_raw))
        done = capture.have >= capture.n_samples
        if not done and self._clock.now() > capture.t_start_s + 2.0 * capture.n_samples / self._odr_hz + 1.0:
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): {capture.have} of {capture.n_samples} "
                                  "samples before the deadline: is it measuring?")
        return done

    def end_capture(self) -> SampleBlock:
        """The completed block, with the temperature the bridge read as it completed."""
        capture = self._capture
        assert capture is not None and capture.have >= capture.n_samples
        self._capture = None
        if capture.temperature_after_c is None:
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): the bridge completed a capture "
                                  "without its end temperature")
        return self._block(capture.pieces, capture.n_samples, capture.t_start_s,
                           (capture.temperature_before_c, capture.temperature_after_c))

    def _block(self, pieces: list[dict[str, np.ndarray]], n_samples: int, t_start: float,
               temperature_c: tuple[float, float]) -> SampleBlock:
        """The pieces of a block, each channel's codes joined and cut to `n_samples`."""
        codes = {name: np.concatenate([piece[name] for piece in pieces])[:n_samples] for name in pieces[0]}
        return SampleBlock(codes, t_start, t_start + (n_samples - 1) / self._odr_hz, temperature_c)

    def _capturing_bus(self) -> BlockCapture:
        """The (retried) transport, as one that captures blocks: only such a one has a capture capacity."""
        bus = self._bus
        if not isinstance(bus, BlockCapture):
            raise InstrumentError(f"sensor {self.serial} ({self.endpoint}): its transport captures no blocks")
        return bus

    def _posted(self, send: Callable[[PostedRequests], None]) -> bool:
        """Send a request with `send` on the bare transport, if it posts requests (no retry: a failure is
        retried whole by the exchange that follows)."""
        if self._poster is None:
            return False
        try:
            send(self._poster)
        except TransientInstrumentError:
            return False
        return True

    def _received(self, posted: bool, receive: Callable[[PostedRequests], T]) -> T | None:
        """The reply to a posted request; None when none was posted or it failed transiently (ask again)."""
        if not posted or self._poster is None:
            return None
        try:
            return receive(self._poster)
        except TransientInstrumentError:
            return None
