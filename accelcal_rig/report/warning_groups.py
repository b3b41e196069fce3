"""A campaign's warnings grouped as a lab reads them: one row per kind of trouble and instrument — how often,
first and last time, and whether it recovered — instead of one raw line per retry attempt.

A warning's source is what its message names before the first `: ` (`chamber (modbus-tcp 10.0.0.7:502)`,
`sensor bridge (serial /dev/ttyACM1)`); what happened is the rest with what varies from one attempt to the
next taken out (the attempt count and backoff, the request quoted, register numbers, a driver library's own
wording after the first clause). A retried request recovered unless the campaign's fault names its source.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

from accelcal_rig.store.records import StoredEvent

_ATTEMPT = re.compile(r";\s*attempt \d+ of \d+.*$")
_QUOTED_REQUEST = re.compile(r"^'[^']*':\s*")
_NUMBER = re.compile(r"\b\d+(\.\d+)?\b")
_QUOTED = re.compile(r"'[^']*'")


@dataclass(frozen=True)
class WarningGroup:
    kind: str                 # the event kind: retry, soak, fit, frost, …
    source: str               # the instrument or subject the messages name ("" when none is named)
    what: str                 # the trouble, its varying parts generalised
    count: int
    first_s: float            # campaign clock
    last_s: float
    recovered: bool | None    # retries: whether the run went on (no fault named the source); else None
    last_message: str         # the latest message whole

    def as_dict(self) -> dict[str, object]:
        return {"kind": self.kind, "source": self.source, "what": self.what, "count": self.count,
                "first_s": self.first_s, "last_s": self.last_s, "recovered": self.recovered,
                "last_message": self.last_message}


def _split(message: str) -> tuple[str, str]:
    """(source, what) of a warning's message."""
    source, separator, rest = message.partition(": ")
    if not separator:  # nothing named: the whole message is what happened
        source, rest = "", message
    rest = _QUOTED_REQUEST.sub("", _ATTEMPT.sub("", rest))
    what = _QUOTED.sub("'…'", rest.split(": ", 1)[0])
    return source, _NUMBER.sub("N", what).strip()


def warning_groups(events: Iterable[StoredEvent]) -> list[WarningGroup]:
    """The warnings and errors of `events` grouped by (kind, source, what), in order of first appearance; the
    campaign's abort is not a warning to group (it is the campaign's state)."""
    events = list(events)
    faults = [e for e in events if e.kind == "fault"]
    rows: dict[tuple[str, str, str], list[StoredEvent]] = {}
    for event in events:
        if event.level not in ("warning", "error") or event.kind == "fault":
            continue
        source, what = _split(event.message)
        rows.setdefault((event.kind, source, what), []).append(event)
    groups = []
    for (kind, source, what), found in rows.items():
        recovered = None
        if kind == "retry":
            recovered = not any(source and source in fault.message and fault.t_s >= found[0].t_s for fault in faults)
        groups.append(WarningGroup(kind, source, what, len(found), found[0].t_s, found[-1].t_s, recovered,
                                   found[-1].message))
    return groups
