"""Where a campaign stopped and was resumed, read from its journal: each resuming run records its start
(store/records.py RunStart, wall clock) and a `resume` event on the campaign clock; the record before that
event is the last the stopped run wrote. An operator reads from them when the rig was down and for how long;
the temperature plot marks them (a real clock runs on while the rig is down: the gap shows there too)."""

from __future__ import annotations

import datetime as dt
import re
from dataclasses import asdict, dataclass
from typing import Any

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.web.svg import Marker

#: engine/session.py's event as a run resumes: which run, and the state the last run left the file in.
_RESUMES = re.compile(r"run (\d+) resumes after \d+ stored poses \(the last run left the file '(\w+)'\)")
_ABORTED = "campaign aborted"
#: What a run that left its file `created` or `running` did: it never closed it.
DIED = "its process ended without closing the file (killed, or the computer stopped)"


@dataclass(frozen=True)
class Interruption:
    run: int                       #: the run that resumed the campaign (2, 3, …)
    stopped: str                   #: wall time of the stopped run's last record (ISO 8601), "" when none
    stopped_clock_s: float | None  #: the campaign clock then
    resumed: str                   #: wall time the resuming run started
    resumed_clock_s: float         #: the campaign clock as it resumed
    down_s: float | None           #: wall time between the two, None when either cannot be read
    why: str                       #: the stopped run's reason, or that it died

    @property
    def gap_s(self) -> float:
        """How far the campaign clock moved while nothing was recorded (0 on a dry run's virtual clock)."""
        return max(0.0, self.resumed_clock_s - self.stopped_clock_s) if self.stopped_clock_s is not None else 0.0

    def as_dict(self) -> dict[str, Any]:
        """As the dashboard's JSON and page show it: times as `rig status` writes them."""
        return {**asdict(self), "gap_s": self.gap_s,
                "down": format_duration(self.down_s) if self.down_s is not None else None,
                "stopped_clock": format_duration(self.stopped_clock_s) if self.stopped_clock_s is not None else None,
                "resumed_clock": format_duration(self.resumed_clock_s)}


def interruptions(campaign: Any) -> list[Interruption]:
    """Each stop a run resumed, oldest first (a campaign run once has none)."""
    started = {run.run: run.started for run in campaign.runs}
    found = []
    for index, event in enumerate(campaign.events):
        resumed = _RESUMES.fullmatch(event.message) if event.kind == "resume" else None
        if resumed is None:
            continue
        run, left = int(resumed[1]), resumed[2]
        before = campaign.events[index - 1] if index > 0 else None
        resumed_at = started.get(run) or event.wall_time
        found.append(Interruption(
            run=run, stopped=before.wall_time if before else "", stopped_clock_s=before.t_s if before else None,
            resumed=resumed_at, resumed_clock_s=event.t_s,
            down_s=_seconds_between(before.wall_time, resumed_at) if before else None,
            why=DIED if left in ("created", "running") else _abort_reason(campaign.events[:index])))
    return found


def resume_markers(stops: list[Interruption]) -> list[Marker]:
    """Each resume on a plot against campaign time in hours, the gap before it shaded where the clock ran on."""
    return [Marker(stop.resumed_clock_s / 3600.0, f"run {stop.run}",
                   stop.stopped_clock_s / 3600.0 if stop.gap_s > 0 and stop.stopped_clock_s is not None else None)
            for stop in stops]


def _abort_reason(events: list[Any]) -> str:
    """The stopped run's last word on why it aborted (its error event), else that it did not say."""
    for event in reversed(events):
        if event.level == "error" and event.message.startswith(_ABORTED) and ": " in event.message:
            return event.message.split(": ", 1)[1]
        if event.kind == "resume":  # an earlier run's: this one said nothing
            break
    return "not recorded"


def _seconds_between(first: str, second: str) -> float | None:
    try:
        return max(0.0, (dt.datetime.fromisoformat(second) - dt.datetime.fromisoformat(first)).total_seconds())
    except (ValueError, TypeError):  # a time a damaged record holds, or one without a zone beside one with
        return None
