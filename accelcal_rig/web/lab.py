"""The dashboard's view of a lab's rigs: the overview of what every rig's campaigns publish to the registry,
a published campaign's page, and the server-sent events that tell an open page to fetch the overview again
(when the registry says something changed, and every TICK_S besides, so that a rig going quiet is shown
as such within STALE_AFTER_S + TICK_S without anything being published)."""

from __future__ import annotations

import asyncio
import re
import threading
import time
from collections.abc import AsyncIterator, Callable
from typing import Any

from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import StreamingResponse

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.errors import RigError
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.live import LiveBoard
from accelcal_rig.report.warning_groups import warning_groups
from accelcal_rig.store.records import StoredEvent
from accelcal_rig.web.live_watch import LiveChanges
from accelcal_rig.web.rigs import EndedInFile, as_file_says, campaign_view, overview, rig_cards
from accelcal_rig.web.svg import line_plot

#: Longest wait between two events of the stream (a page re-reads the overview at each).
TICK_S = 10.0
#: Shortest wait between two `change` events (a dry run publishes many a second; a page needs one).
CHANGE_EVERY_S = 1.0
#: A stream ends after this long; the browser opens it again by itself (EventSource), so no connection is
#: held for ever by a page left open.
STREAM_S = 300.0
#: Events shown on a published campaign's page (the newest).
EVENTS_SHOWN = 50
_KEY = re.compile(r"^[0-9a-f]{32}$")


class LabRigs:
    def __init__(self, registry: Callable[[], Registry],
                 on_failure: Callable[[BaseException], None] = lambda exc: None,
                 ended: EndedInFile | None = None) -> None:
        self._registry = registry
        self._on_failure = on_failure  # a registry that failed here is taken as down (web/registry_gate.py)
        #: What the watched campaign files say of a campaign the registry last heard running (web/rigs.py).
        self._ended: EndedInFile = ended or (lambda host, campaign: None)
        self.changes = LiveChanges(self.board)
        self.stopping = threading.Event()  # the server is stopping: every stream ends

    def stop_streams(self) -> None:
        self.stopping.set()
        self.changes.stop()

    def board(self) -> LiveBoard:
        return LiveBoard(self._registry())

    def overview(self) -> dict[str, Any]:
        """{lab: the cards and recent campaigns, rigs_error: why there are none to show (no registry yet, one
        that cannot be read), else None}."""
        try:
            return {"lab": overview(self.board(), self._ended), "rigs_error": None}
        except RigError as exc:
            self._on_failure(exc)
            return {"lab": None, "rigs_error": str(exc).splitlines()[0]}

    def campaign(self, key: str) -> dict[str, Any]:
        """A published campaign's page values; 404 for one never published."""
        board = self.board()
        row = board.campaign(key) if _KEY.match(key) else None
        if row is None:
            raise HTTPException(404, f"no campaign {key} published to the registry")
        now = board.now()
        view = as_file_says(campaign_view(row, now), self._ended)
        events = board.events(key)
        stored = [StoredEvent(e.clock_s, f"{e.at:%Y-%m-%dT%H:%M:%S}Z", e.level, e.kind, e.message) for e in events]
        groups = [{**g.as_dict(), "first": format_duration(g.first_s), "last": format_duration(g.last_s)}
                  for g in warning_groups(stored)]
        series = board.temperatures(key)
        plot = line_plot(series["t_h"], {"chamber air": series["chamber_c"], "DUTs (mean)": series["dut_c"]},
                         "campaign time (h)", "temperature (°C)")
        shown = [{"clock": format_duration(e.clock_s), "at": f"{e.at:%Y-%m-%d %H:%M:%S}", "level": e.level,
                  "kind": e.kind, "message": e.message} for e in events[-EVENTS_SHOWN:]]
        card = rig_cards([row], now, self._ended)[0]
        return {"c": view, "headline": card.headline, "groups": groups, "plot": plot, "events": shown[::-1]}

    async def stream(self, request: Request) -> StreamingResponse:
        """`text/event-stream`: `change` when the registry's live tables changed, `tick` when nothing did."""
        self.changes.start()

        async def events() -> AsyncIterator[str]:
            yield "retry: 2000\n\n"
            began = sent_at = time.monotonic()
            changed_at, seen = float("-inf"), -1
            while (time.monotonic() - began < STREAM_S and not self.stopping.is_set()
                   and not await request.is_disconnected()):
                now = time.monotonic()
                if self.changes.version != seen and now - changed_at >= CHANGE_EVERY_S:
                    seen, sent_at = self.changes.version, now
                    changed_at = now
                    yield f"event: change\ndata: {seen}\n\n"
                elif now - sent_at >= TICK_S:
                    sent_at = now
                    yield "event: tick\ndata: \n\n"
                await asyncio.sleep(0.25)

        return StreamingResponse(events(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-store", "X-Accel-Buffering": "no"})
