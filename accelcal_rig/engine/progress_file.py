"""A running campaign's latest snapshot on disk (FILE.progress.json), so that `rig status` and `rig serve`
show its phase, temperatures and time left from another process, without touching its writer.

Written at most every half second of wall time and at every change of phase, each time whole (a new file
renamed over the old: a reader never sees half of one). It is a view, not a record: a crash may leave it
stale, which its `updated` time and the writer's liveness tell."""

from __future__ import annotations

import dataclasses
import json
import os
import time
from datetime import UTC, datetime
from pathlib import Path

from accelcal_rig.durable import temporary_beside
from accelcal_rig.engine.progress import Progress, ProgressListener

#: Shortest wall-clock interval between two writes within one phase.
MIN_INTERVAL_S = 0.5


class ProgressFile:
    def __init__(self, path: Path, then: ProgressListener | None = None) -> None:
        self._path = path
        self._then = then
        self._written_at = float("-inf")
        self._phase: tuple[str, int] | None = None

    def __call__(self, progress: Progress) -> None:
        if self._then is not None:
            self._then(progress)
        now = time.monotonic()
        phase = (progress.phase, progress.setpoint_number)
        if phase == self._phase and now - self._written_at < MIN_INTERVAL_S:
            return
        self._phase, self._written_at = phase, now
        snapshot = {**dataclasses.asdict(progress), "line": progress.line(), "pid": os.getpid(),
                    "updated": datetime.now(UTC).isoformat(timespec="seconds")}
        temporary = temporary_beside(self._path)
        try:
            temporary.write_text(json.dumps(snapshot))
            os.replace(temporary, self._path)
        except OSError:
            pass  # a view for watchers: a full disk must not stop the campaign (the journal says so itself)
