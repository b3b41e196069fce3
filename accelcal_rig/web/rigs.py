"""Every rig of a lab at a glance, from what their campaigns publish to the shared registry
(registry/live.py): one card per rig — running with its progress and time left, not heard from, aborted
with why, done with each DUT's verdict, idle — and the recent campaigns of all of them."""

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


def rig_cards(rows: list[dict[str, Any]], now: datetime) -> list[RigCard]:
    """One card per rig (by its name and computer), in name order: the campaign it runs now, else its latest."""
    by_rig: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for row in rows:
        by_rig.setdefault((row["rig"], row["host"]), []).append(row)
    cards = []
    for (rig, host), mine in sorted(by_rig.items()):
        running = [r for r in mine if r["state"] == "running"]
        shown = max(running or mine, key=lambda r: (r["updated_at"], r["started_at"]))
        view = campaign_view(shown, now)
        status = view["status"]
        if status not in ("running", "silent") and now - shown["updated_at"] > IDLE_AFTER:
            status = "idle"
        cards.append(RigCard(rig, host, status, _headline(status, view), view))
    return cards


def overview(board: LiveBoard) -> dict[str, Any]:
    """The cards and the recent campaigns, as the front page and /api/rigs give them."""
    rows = board.campaigns(limit=None)
    now = board.now()
    return {"now": f"{now:%Y-%m-%d %H:%M:%S} UTC", "rigs": [card.as_dict() for card in rig_cards(rows, now)],
            "campaigns": [campaign_view(row, now) for row in rows[:RECENT]]}


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
    return words.get(status, lambda: status)()


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
