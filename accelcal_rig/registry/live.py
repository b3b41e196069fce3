"""Live status in the registry database: what each running campaign publishes as it runs (its latest snapshot,
its events, its temperatures) and what a dashboard reads back to show every rig of a lab in one window.

The campaign file stays the truth: these rows are a view of it, replaced as it advances. Freshness is judged
on the database's own clock (`updated_at` is written as the database's time, and read beside it), so two
computers whose clocks disagree still agree on which rig went quiet. On PostgreSQL every write notifies the
`accelcal_live` channel (LISTEN/NOTIFY), so a dashboard learns of it at once; SQLite is polled."""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from accelcal_rig.registry.database import Registry, reads
from accelcal_rig.registry.schema import live_campaigns, live_events, live_temperatures

#: The PostgreSQL notification channel a write announces itself on (its payload: the campaign's key).
CHANNEL = "accelcal_live"
#: A campaign shown as running whose last word is older than this is shown as not heard from.
STALE_AFTER_S = 45.0
#: Events kept per campaign (the newest; a campaign retrying for hours must not grow the table without end).
EVENTS_KEPT = 2000
#: SQLite's clock as SQLAlchemy stores a DateTime (microseconds: its milliseconds and three zeros).
_SQLITE_NOW = "%Y-%m-%d %H:%M:%f000"


def campaign_key(host: str, campaign_path: str) -> str:
    """One campaign file on one computer: its resumed runs continue the same row."""
    return hashlib.sha256(f"{host}\0{campaign_path}".encode()).hexdigest()[:32]


@dataclass(frozen=True)
class LiveEvent:
    clock_s: float
    at: datetime            # UTC, naive
    level: str
    kind: str
    message: str


class LiveBoard:
    """The live tables of one registry."""

    def __init__(self, registry: Registry) -> None:
        self.registry = registry
        self.engine = registry.engine

    # ------------------------------------------------------------------ writing (the publisher)
    def begin(self, key: str, row: dict[str, Any], fresh: bool) -> None:
        """A run starts publishing: its row written; `fresh` (a new campaign in the file, not a resumed one):
        what an earlier campaign of the same file published is removed first."""
        with self.engine.begin() as connection:
            if fresh:
                for table in (live_events, live_temperatures):
                    connection.execute(sa.delete(table).where(table.c.key == key))
            connection.execute(sa.delete(live_campaigns).where(live_campaigns.c.key == key))
            connection.execute(sa.insert(live_campaigns).values(key=key, updated_at=self._now(), **row))
            self._announce(connection, key)

    def publish(self, key: str, row: dict[str, Any], events: Iterable[LiveEvent] = (),
                temperatures: Iterable[tuple[float, float | None, float | None]] = ()) -> None:
        """The snapshot replaced, new events and temperature points added, in one transaction."""
        events, temperatures = list(events), list(temperatures)
        with self.engine.begin() as connection:
            connection.execute(sa.update(live_campaigns).where(live_campaigns.c.key == key)
                               .values(updated_at=self._now(), **row))
            if events:
                connection.execute(sa.insert(live_events), [
                    {"key": key, "clock_s": e.clock_s, "at": e.at, "level": e.level, "kind": e.kind[:32],
                     "message": e.message} for e in events])
                self._trim_events(connection, key)
            if temperatures:
                connection.execute(sa.insert(live_temperatures), [
                    {"key": key, "clock_s": t, "chamber_c": chamber, "dut_c": dut} for t, chamber, dut in temperatures])
            self._announce(connection, key)

    def _trim_events(self, connection: Connection, key: str) -> None:
        keep_from = connection.execute(
            sa.select(live_events.c.id).where(live_events.c.key == key).order_by(live_events.c.id.desc())
            .offset(EVENTS_KEPT).limit(1)).scalar()
        if keep_from is not None:
            connection.execute(sa.delete(live_events).where(live_events.c.key == key, live_events.c.id <= keep_from))

    def _now(self) -> Any:
        """The database's clock, in UTC (what freshness is judged on)."""
        if self.engine.dialect.name == "postgresql":
            return sa.text("(now() AT TIME ZONE 'UTC')")
        return sa.func.strftime(_SQLITE_NOW, "now")

    def _announce(self, connection: Connection, key: str) -> None:
        if self.engine.dialect.name == "postgresql":  # delivered when the transaction commits
            connection.execute(sa.select(sa.func.pg_notify(CHANNEL, key)))

    # ------------------------------------------------------------------ reading (the dashboard)
    @reads
    def now(self) -> datetime:
        """The database's clock (UTC, naive)."""
        with self.engine.connect() as connection:
            if self.engine.dialect.name == "postgresql":
                value = connection.execute(sa.text("SELECT now() AT TIME ZONE 'UTC'")).scalar_one()
            else:
                value = datetime.fromisoformat(connection.execute(sa.select(sa.func.strftime(_SQLITE_NOW, "now")))
                                               .scalar_one())
        return value.replace(tzinfo=None)

    @reads
    def campaigns(self, limit: int | None = 500) -> list[dict[str, Any]]:
        """Every campaign published (the `limit` newest), newest word first, each with `silent_s` and `stale`:
        shown as running but not heard from for STALE_AFTER_S."""
        query = sa.select(live_campaigns).order_by(live_campaigns.c.updated_at.desc())
        return self._judged(query.limit(limit) if limit is not None else query)

    @reads
    def campaign(self, key: str) -> dict[str, Any] | None:
        rows = self._judged(sa.select(live_campaigns).where(live_campaigns.c.key == key))
        return rows[0] if rows else None

    def _judged(self, query: sa.Select[Any]) -> list[dict[str, Any]]:
        """The rows with how long each has been silent, on the database's clock, and whether it is stale."""
        with self.engine.connect() as connection:
            rows = [dict(row._mapping) for row in connection.execute(query)]
        now = self.now()
        for row in rows:
            row["silent_s"] = max(0.0, (now - row["updated_at"]).total_seconds())
            row["stale"] = row["state"] == "running" and row["silent_s"] > STALE_AFTER_S
        return rows

    @reads
    def events(self, key: str) -> list[LiveEvent]:
        query = (sa.select(live_events.c.clock_s, live_events.c.at, live_events.c.level, live_events.c.kind,
                           live_events.c.message).where(live_events.c.key == key).order_by(live_events.c.id))
        with self.engine.connect() as connection:
            return [LiveEvent(float(c), at, str(level), str(kind), str(message))
                    for c, at, level, kind, message in connection.execute(query)]

    @reads
    def temperatures(self, key: str) -> dict[str, list[float]]:
        """The campaign's published temperatures, as the local campaign page plots them."""
        query = (sa.select(live_temperatures.c.clock_s, live_temperatures.c.chamber_c, live_temperatures.c.dut_c)
                 .where(live_temperatures.c.key == key).order_by(live_temperatures.c.clock_s))
        with self.engine.connect() as connection:
            points = list(connection.execute(query))
        nan = float("nan")
        return {"t_h": [float(t) / 3600.0 for t, _, _ in points],
                "chamber_c": [nan if c is None else float(c) for _, c, _ in points],
                "dut_c": [nan if d is None else float(d) for _, _, d in points]}

    @reads
    def version(self) -> tuple[Any, int]:
        """What changes whenever anything is published (polled where there is no LISTEN/NOTIFY)."""
        with self.engine.connect() as connection:
            latest, count = connection.execute(
                sa.select(sa.func.max(live_campaigns.c.updated_at), sa.func.count())).one()
        return latest, int(count)
