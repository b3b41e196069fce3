"""The registry database: opened by URL, created on first use and brought to the current schema by the
commands that record (Alembic, under a lock so that two rigs opening it at once do not both migrate it),
written so that concurrent writers never lose a record (batches in their own transactions, a duplicate of
a registered fit skipped by its unique key, a transaction that lost a deadlock tried again)."""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from datetime import datetime
from pathlib import Path
from typing import Any

import sqlalchemy as sa
from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from alembic.util.exc import CommandError
from sqlalchemy.dialects import postgresql, sqlite
from sqlalchemy.engine import Connection, Engine

from accelcal_rig.errors import ConfigError
from accelcal_rig.registry.location import described
from accelcal_rig.registry.schema import approvals, calibrations

_MIGRATIONS = Path(__file__).parent / "migrations"
#: A PostgreSQL advisory lock key for schema migrations (any constant the lab's other users do not take).
_MIGRATION_LOCK = 0x0ACCE1CA1
#: Tries to open a registry another process is opening at the same moment (SQLite).
_OPEN_ATTEMPTS = 20
#: Entries per insert transaction.
_BATCH = 500
#: SQLite waits this long for another writer's lock before giving up.
_SQLITE_BUSY_S = 60.0
#: The verdict of a calibration no acceptance limits judged: stored as none (NULL), counted in no yield.
NOT_JUDGED = "NOT JUDGED"


def migration_config() -> Config:
    config = Config()
    config.set_main_option("script_location", str(_MIGRATIONS))
    return config


def known_revisions() -> set[str]:
    return {script.revision for script in ScriptDirectory.from_config(migration_config()).walk_revisions()}


def head_revision() -> str:
    head = ScriptDirectory.from_config(migration_config()).get_current_head()
    assert head is not None
    return head


class Registry:
    def __init__(self, engine: Engine, url: str) -> None:
        self.engine = engine
        self.url = url

    @classmethod
    def open(cls, url: str, upgrade: bool = True, create: bool = True) -> Registry:
        """Connect. A new, empty database is created at the current schema when `create` (the commands that
        record; a reader is refused in one line instead); an older one is migrated when `upgrade`, else
        refused in one line (readers do not change a schema); one newer than this software is refused
        either way."""
        if not create and url.startswith("sqlite:///") and not Path(url.removeprefix("sqlite:///")).is_file():
            raise ConfigError(f"registry {described(url)}: does not exist (nothing recorded in it yet)")
        engine = _engine(url)
        registry = cls(engine, url)
        for attempt in range(_OPEN_ATTEMPTS):
            try:
                found = registry.revision()
                if found is not None and found not in known_revisions():
                    raise ConfigError(f"registry {described(url)}: schema {found} is newer than this software's "
                                      f"{head_revision()}: upgrade accelcal-rig")
                if found is None or (upgrade and found != head_revision()):
                    registry.upgrade()
                elif found != head_revision():
                    raise ConfigError(f"registry {described(url)}: schema {found} is older than this software's "
                                      f"{head_revision()}: a recording command (rig registry add, rig fit) upgrades it")
                return registry
            except sa.exc.OperationalError as exc:
                # SQLite answers "locked" at once, busy timeout or not, to a connection switching a new file
                # to WAL while another does: the other is done in a moment.
                if "locked" not in str(exc.orig) or attempt == _OPEN_ATTEMPTS - 1:
                    raise ConfigError(f"registry {described(url)}: cannot open: {exc.orig}") from None
                time.sleep(0.05 * (attempt + 1))
            except (sa.exc.SQLAlchemyError, CommandError) as exc:
                raise ConfigError(f"registry {described(url)}: {str(exc).splitlines()[0]}") from None
        raise AssertionError("unreachable")

    def upgrade(self, revision: str = "head") -> None:
        """Apply every migration not applied yet, one process at a time."""
        with self._migration_lock() as connection:
            config = migration_config()
            config.attributes["connection"] = connection
            command.upgrade(config, revision)

    def revision(self) -> str | None:
        with self.engine.connect() as connection:
            return MigrationContext.configure(connection).get_current_revision()

    # ------------------------------------------------------------------ writing
    def add(self, entries: Iterable[dict[str, Any]]) -> tuple[list[int], int]:
        """Record each entry; (ids of those added, how many were registered already). Entries go in batches,
        each its own transaction: a batch is all there or not at all, and one already registered is skipped."""
        pending = sorted(entries, key=lambda e: (e["source_sha256"], e["serial"], e["fit_sha256"]))  # one lock order
        added: list[int] = []
        for start in range(0, len(pending), _BATCH):
            batch = pending[start:start + _BATCH]
            added += self._insert(batch)
        return added, len(pending) - len(added)

    def _insert(self, batch: list[dict[str, Any]]) -> list[int]:
        """The ids of the entries of `batch` not registered before, inserted in one transaction."""
        dialect = self.engine.dialect.name
        insert = postgresql.insert(calibrations) if dialect == "postgresql" else sqlite.insert(calibrations)
        statement = insert.on_conflict_do_nothing(index_elements=["source_sha256", "serial", "fit_sha256"])
        for attempt in range(10):
            try:
                with self.engine.begin() as connection:
                    result = connection.execute(statement.returning(calibrations.c.id), batch)
                    return [int(row_id) for row_id in result.scalars()]
            except sa.exc.OperationalError as exc:  # SQLite past its busy timeout; PostgreSQL a lost deadlock
                again = ("locked" in str(exc.orig) if dialect == "sqlite"
                         else getattr(exc.orig, "sqlstate", None) in ("40P01", "40001"))
                if not again or attempt == 9:
                    raise
                time.sleep(0.1 * (attempt + 1))
        raise AssertionError("unreachable")

    # ------------------------------------------------------------------ reading
    def calibrations(self, serial: str | None = None, part: str | None = None, since: datetime | None = None,
                     verdict: str | None = None, limit: int | None = None,
                     channel: str | None = None, simulated: bool | None = None) -> list[dict[str, Any]]:
        """Rows, newest calibration first, filtered as given (`channel`: only that channel's, else every
        channel's, each row saying which; `verdict` NOT JUDGED: those stored with none; `simulated`: only dry
        runs, or only real calibrations); without the stored fit (`calibration(id)` has it: a lot of thousands
        of sensors is listed without reading thousands of fits)."""
        listed = [column for column in calibrations.columns if column.name != "calibration"]
        query = sa.select(*listed).order_by(calibrations.c.calibrated_at.desc(), calibrations.c.id.desc())
        if serial is not None:
            query = query.where(calibrations.c.serial == serial)
        if part is not None:
            query = query.where(calibrations.c.part == part)
        if since is not None:
            query = query.where(calibrations.c.calibrated_at >= since)
        if verdict == NOT_JUDGED:
            query = query.where(calibrations.c.verdict.is_(None))
        elif verdict is not None:
            query = query.where(calibrations.c.verdict == verdict)
        if simulated is not None:
            query = query.where(calibrations.c.simulated if simulated else sa.not_(calibrations.c.simulated))
        if channel is not None:
            query = query.where(calibrations.c.channel == channel)
        if limit is not None:
            query = query.limit(limit)
        with self.engine.connect() as connection:
            return [dict(row._mapping) for row in connection.execute(query)]

    def calibration(self, row_id: int) -> dict[str, Any]:
        """One calibration's row with its stored fit."""
        with self.engine.connect() as connection:
            row = connection.execute(sa.select(calibrations).where(calibrations.c.id == row_id)).first()
        if row is None:
            raise ConfigError(f"registry {described(self.url)}: no calibration {row_id}")
        return dict(row._mapping)

    def current(self, serial: str, simulated: bool = False, channel: str = "accel") -> dict[str, Any] | None:
        """The valid calibration of a serial's channel: its newest approved real calibration, unless a newer
        one failed its acceptance limits and was not rejected (the sensor is out of tolerance now: none is
        valid; an approved FAIL confirms it). A calibration awaiting approval is not valid yet; a rejected one
        never. Dry runs, only when
        asked, count as their newest unless failed: they are never a lab's valid calibration."""
        rows = [r for r in self.calibrations(serial=serial, channel=channel) if simulated or not r["simulated"]]
        if simulated:
            return rows[0] if rows and rows[0]["verdict"] != "FAIL" else None
        decided = self.last_actions([r["id"] for r in rows])
        for row in rows:
            action = decided.get(row["id"])
            if row["verdict"] == "FAIL" and action != "reject":  # approved or not, the sensor failed
                return None
            if action in ("approve", "reissue"):
                return row
        return None

    def why_not_valid(self, serial: str, channel: str = "accel") -> str:
        """Why a serial's channel has no valid calibration (current() is None), in a few words."""
        rows = [r for r in self.calibrations(serial=serial, channel=channel) if not r["simulated"]]
        if not rows:
            return "only dry runs (simulated) are recorded: --simulated shows them"
        decided = self.last_actions([r["id"] for r in rows])
        failed = next((r for r in rows if r["verdict"] == "FAIL" and decided.get(r["id"]) != "reject"), None)
        approved = next((r for r in rows if decided.get(r["id"]) in ("approve", "reissue")), None)
        if failed is not None and (approved is None or failed["calibrated_at"] >= approved["calibrated_at"]):
            return (f"calibration {failed['id']} failed its acceptance limits and is the newest not rejected: the "
                    "sensor is out of tolerance")
        return "none approved: a calibration awaiting approval or rejected is not valid (rig approve)"

    def ids_of(self, entries: list[dict[str, Any]]) -> dict[str, int]:
        """Of recorded entries (registry/entries.py), each serial's first row: its DUT's calibration's lead.
        A serial whose entries are not all recorded is left out."""
        found: dict[str, list[int | None]] = {}
        with self.engine.connect() as connection:
            for entry in entries:
                row_id = connection.execute(sa.select(calibrations.c.id).where(
                    calibrations.c.source_sha256 == entry["source_sha256"], calibrations.c.serial == entry["serial"],
                    calibrations.c.fit_sha256 == entry["fit_sha256"])).scalar()
                found.setdefault(entry["serial"], []).append(row_id)
        return {serial: min(i for i in ids if i is not None) for serial, ids in found.items() if None not in ids}

    def last_actions(self, ids: list[int]) -> dict[int, str]:
        """The latest approval action (approve, reject, reissue) recorded on each of these rows that has one."""
        if not ids:
            return {}
        query = (sa.select(approvals.c.calibration_id, approvals.c.action)
                 .where(approvals.c.calibration_id.in_(ids)).order_by(approvals.c.id))
        with self.engine.connect() as connection:
            return {int(i): str(action) for i, action in connection.execute(query)}

    def channels(self, serial: str | None = None) -> list[str]:
        """Every channel with a calibration recorded (of one serial, if given): `accel` first."""
        query = sa.select(calibrations.c.channel).distinct()
        if serial is not None:
            query = query.where(calibrations.c.serial == serial)
        with self.engine.connect() as connection:
            return sorted(connection.execute(query).scalars(), key=lambda c: (c != "accel", c))

    def parts(self) -> list[str]:
        """Every part with a calibration recorded."""
        with self.engine.connect() as connection:
            return sorted(connection.execute(sa.select(calibrations.c.part).distinct()).scalars())

    def count(self) -> int:
        with self.engine.connect() as connection:
            return int(connection.execute(sa.select(sa.func.count()).select_from(calibrations)).scalar_one())

    @contextmanager
    def _migration_lock(self) -> Iterator[Connection]:
        """A connection whose transaction holds the schema for this process alone: PostgreSQL's
        transaction-level advisory lock (released with the transaction, whatever happens in it), SQLite's
        write lock (BEGIN IMMEDIATE)."""
        with self.engine.connect() as connection:
            if self.engine.dialect.name == "postgresql":
                with connection.begin():
                    connection.execute(sa.text("SET LOCAL lock_timeout = '120s'"))
                    connection.execute(sa.text("SELECT pg_advisory_xact_lock(:key)"), {"key": _MIGRATION_LOCK})
                    yield connection
            else:
                connection.info["begin"] = "BEGIN IMMEDIATE"  # see _engine's begin hook
                try:
                    yield connection
                    connection.commit()
                finally:
                    connection.info.pop("begin", None)


def _engine(url: str) -> Engine:
    if url.startswith("sqlite:///"):
        path = Path(url.removeprefix("sqlite:///"))
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ConfigError(f"registry {url}: cannot create its folder: {exc}") from None
        engine = sa.create_engine(url, connect_args={"timeout": _SQLITE_BUSY_S}, poolclass=sa.pool.NullPool)

        @sa.event.listens_for(engine, "connect")
        def _pragmas(dbapi_connection: Any, _: Any) -> None:
            dbapi_connection.isolation_level = None  # SQLAlchemy's BEGIN, not pysqlite's own
            cursor = dbapi_connection.cursor()
            cursor.execute("PRAGMA journal_mode=WAL")  # readers never block the writer, nor it them
            cursor.execute(f"PRAGMA busy_timeout={int(_SQLITE_BUSY_S * 1000)}")
            cursor.execute("PRAGMA foreign_keys=ON")  # a decision names a calibration that exists
            cursor.close()

        @sa.event.listens_for(engine, "begin")
        def _begin(connection: Connection) -> None:
            connection.exec_driver_sql(connection.info.get("begin", "BEGIN"))
        return engine
    try:
        return sa.create_engine(url, pool_pre_ping=True)
    except (sa.exc.ArgumentError, ModuleNotFoundError) as exc:
        raise ConfigError(f"registry {described(url)}: {exc} (PostgreSQL needs: pip install "
                          "'accelcal-rig[postgresql]')") from None
