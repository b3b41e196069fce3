"""Every rig of a lab at a glance, from what their campaigns publish to the shared registry
(registry/live.py): one card per rig — running with its progress and time left, not heard from, aborted
with why, done with each DUT's verdict, idle — and the recent campaigns of all of them. A campaign the
registry last heard running whose file, in a folder the dashboard watches, says it ended is shown as its file
says (its last update never reached the registry: a kill after the last pose, the registry down at the end)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import PurePath
from typing import Any

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.registry.live import LiveBoard

#: A rig whose last campaign ended this long ago is idle (its last campaign is still shown, smaller).
IDLE_AFTER = timedelta(hours=12)
#: Campaigns listed under the cards.
RECENT = 50
#: What a watched campaign file says of a campaign (host, path): its summary (web/campaigns.py) when it ended,
#: else None.
EndedInFile = Callable[[str, str], "dict[str, Any] | None"]


def _not_watched(host: str, campaign: str) -> dict[str, Any] | None:
    return None


@dataclass(frozen=True)
class RigCard:
    rig: str
    host: str
    status: str                    # running | silent | aborted | done | stopped | idle
    headline: str                  # what the card says first
    campaign: dict[str, Any]       # the campaign the card shows (a live row, see campaign_view)

    def as_dict(self) -> dict[str, Any]:
        return {"rig": self.rig, "host": self.host, "status": self.status, "headline": self.headline,
                "campaign": self.campaign}


def campaign_view(row: dict[str, Any], now: datetime) -> dict[str, Any]:
    """A published campaign as the pages show it: its row with its status, times and counts in words."""
    status = "silent" if row["stale"] else row["state"]
    total = int(row["poses_total"]) or 1
    view = {key: value for key, value in row.items() if key not in ("updated_at", "started_at")}
    view.update(
        status=status, name=PurePath(str(row["campaign"])).name,
        percent=round(100.0 * int(row["poses_done"]) / total, 1),
        left=format_duration(row["remaining_s"]) if row["remaining_s"] is not None else None,
        started=f"{row['started_at']:%Y-%m-%d %H:%M} UTC",
        heard=f"{row['updated_at']:%Y-%m-%d %H:%M:%S} UTC",
        silent=_ago(row["silent_s"]),
        verdict_counts=_verdict_counts(row["verdicts"]),
    )
    return view


def as_file_says(view: dict[str, Any], ended: EndedInFile) -> dict[str, Any]:
    """A campaign not heard from (`silent`) as its campaign file says, when that says it ended."""
    if view["status"] != "silent":
        return view
    found = ended(str(view["host"]), str(view["campaign"]))
    if found is None:
        return view
    verdicts = found.get("verdicts") or {}
    total = int(found.get("poses_total") or view["poses_total"]) or 1
    return {**view, "status": found["state"], "state": found["state"], "stale": False,
            "poses_done": found.get("poses_done", view["poses_done"]), "poses_total": total,
            "percent": round(100.0 * int(found.get("poses_done") or 0) / total, 1), "remaining_s": None,
            "left": None, "abort_reason": found.get("abort_reason") or view.get("abort_reason"),
            "verdicts": verdicts, "verdict_counts": _verdict_counts(verdicts),
            "from_file": f"from its campaign file {found.get('file', '')}: its end never reached the registry"}


def rig_cards(rows: list[dict[str, Any]], now: datetime, ended: EndedInFile = _not_watched) -> list[RigCard]:
    """One card per rig (by its name and computer), in name order: the campaign it runs now, else its latest
    (a silent one as its watched campaign file says, when that says it ended)."""
    by_rig: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for row in rows:
        by_rig.setdefault((row["rig"], row["host"]), []).append(row)
    cards = []
    for (rig, host), mine in sorted(by_rig.items()):
        running = [r for r in mine if r["state"] == "running"]
        shown = max(running or mine, key=lambda r: (r["updated_at"], r["started_at"]))
        view = as_file_says(campaign_view(shown, now), ended)
        status = view["status"]
        if status not in ("running", "silent") and now - shown["updated_at"] > IDLE_AFTER:
            status = "idle"
        cards.append(RigCard(rig, host, status, _headline(status, view), view))
    return cards


def overview(board: LiveBoard, ended: EndedInFile = _not_watched) -> dict[str, Any]:
    """The cards and the recent campaigns, as the front page and /api/rigs give them."""
    rows = board.campaigns(limit=None)
    now = board.now()
    return {"now": f"{now:%Y-%m-%d %H:%M:%S} UTC",
            "rigs": [card.as_dict() for card in rig_cards(rows, now, ended)],
            "campaigns": [as_file_says(campaign_view(row, now), ended) for row in rows[:RECENT]]}


def _headline(status: str, view: dict[str, Any]) -> str:
    words: dict[str, Callable[[], str]] = {
        "running": lambda: f"running · {view['poses_done']}/{view['poses_total']} poses"
                           + (f" · {view['left']} left" if view["left"] else ""),
        "silent": lambda: f"not heard from since {view['heard']} ({view['silent']} ago)",
        "aborted": lambda: f"aborted: {view['abort_reason'] or 'no reason recorded'}",
        "done": lambda: "done · " + (", ".join(f"{n} {v}" for v, n in view["verdict_counts"].items()) or "not judged"),
        "stopped": lambda: f"stopped · {view['poses_done']}/{view['poses_total']} poses",
        "idle": lambda: f"idle · last campaign {view['state']} {view['heard']}",
    }
    said = words.get(status, lambda: status)()
    return f"{said} (its campaign file says so)" if view.get("from_file") else said


def _verdict_counts(verdicts: dict[str, Any]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for judged in (verdicts or {}).values():
        verdict = str((judged or {}).get("verdict") or "NOT JUDGED")
        counts[verdict] = counts.get(verdict, 0) + 1
    return counts


def _ago(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return format_duration(seconds)
