"""The registry database: opened by URL, created on first use and brought to the current schema by the
commands that record (Alembic, under a lock so that two rigs opening it at once do not both migrate it),
written so that concurrent writers never lose a record (batches in their own transactions, a duplicate of
a registered fit skipped by its unique key, a transaction that lost a deadlock tried again)."""

from __future__ import annotations

import functools
import os
import sqlite3
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any, TypeVar
from urllib.parse import quote

import sqlalchemy as sa
from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from alembic.util.exc import CommandError
from sqlalchemy.dialects import postgresql, sqlite
from sqlalchemy.engine import Connection, Engine

from accelcal_rig.core.extras import install_hint
from accelcal_rig.errors import ConfigError
from accelcal_rig.registry.location import described
from accelcal_rig.registry.schema import approvals, calibration_figures, calibrations, registry_tables

T = TypeVar("T")
_MIGRATIONS = Path(__file__).parent / "migrations"
#: A PostgreSQL advisory lock key for schema migrations (any constant the lab's other users do not take).
_MIGRATION_LOCK = 0x0ACCE1CA1
#: Tries to open a registry another process is opening at the same moment (SQLite).
_OPEN_ATTEMPTS = 20
#: Entries per insert transaction.
_BATCH = 500
#: SQLite waits this long for another writer's lock before giving up.
_SQLITE_BUSY_S = 60.0
#: Seconds a PostgreSQL registry is given to answer a connection (the URL's own `connect_timeout` instead, if
#: it has one).
CONNECT_TIMEOUT_S = 10
#: The verdict of a calibration no acceptance limits judged: stored as none (NULL), counted in no yield.
NOT_JUDGED = "NOT JUDGED"


@dataclass(frozen=True)
class RegistryTimeouts:
    """How long a registry is waited for: a connection (PostgreSQL's connect_timeout, unless the URL gives one;
    TCP's user timeout the same), a statement (PostgreSQL's statement_timeout; None: no limit), SQLite's lock.
    The commands' defaults wait long (a busy lab's registry); the dashboard waits little (web/registry_gate.py)."""

    connect_s: float = CONNECT_TIMEOUT_S
    statement_s: float | None = None
    sqlite_busy_s: float = _SQLITE_BUSY_S


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


def reads(method: Callable[..., T]) -> Callable[..., T]:
    """A reading method of the registry (or of what reads through it): what its database holds is input like
    any file's, so a row that cannot be read (a table or column gone, a date that is not a date, a value of
    the wrong type written by hand) is one line naming the registry, not a failure of the program."""
    @functools.wraps(method)
    def read(self: Any, *args: Any, **kwargs: Any) -> T:
        try:
            return method(self, *args, **kwargs)
        except (sa.exc.SQLAlchemyError, ValueError, TypeError, KeyError) as exc:
            url = self.url if isinstance(self, Registry) else self.registry.url
            raise ConfigError(f"registry {described(url)}: cannot be read ({_first_line(getattr(exc, 'orig', None) or exc)}): the database "
                              "was damaged or changed by hand") from None
    return read


class Registry:
    def __init__(self, engine: Engine, url: str) -> None:
        self.engine = engine
        self.url = url

    @contextmanager
    def writing(self) -> Iterator[Connection]:
        """A transaction that reads then writes: on SQLite begun IMMEDIATE, so that it waits its turn for the
        write lock (busy timeout) instead of failing at once when its read would have to become a write while
        another writer holds the lock; on PostgreSQL an ordinary one."""
        with self.engine.connect() as connection:
            if self.engine.dialect.name == "sqlite":
                connection.info["begin"] = "BEGIN IMMEDIATE"  # see _engine's begin hook
            try:
                with connection.begin():
                    yield connection
            finally:
                connection.info.pop("begin", None)

    @classmethod
    def open(cls, url: str, upgrade: bool = True, create: bool = True, read_only: bool = False,
             timeouts: RegistryTimeouts | None = None) -> Registry:
        """Connect, in one line when it cannot be. A new, empty database is created at the current schema when
        `create` (the commands that record; a reader is refused instead: it never creates a registry); an
        older one is migrated when `upgrade`, else refused (readers do not change a schema); one newer than
        this software, a foreign database and one that lost a table are refused either way. `read_only`:
        a reader's connection, which can read a registry on a read-only mount and writes nothing."""
        if not create and url.startswith("sqlite:///") and not Path(url.removeprefix("sqlite:///")).is_file():
            raise ConfigError(f"registry {described(url)}: does not exist (nothing recorded in it yet)")
        engine = _engine(url, create=create, read_only=read_only, timeouts=timeouts or RegistryTimeouts())
        registry = cls(engine, url)
        for attempt in range(_OPEN_ATTEMPTS):
            try:
                found = registry.revision()
                if found is not None and found not in known_revisions():
                    raise ConfigError(f"registry {described(url)}: schema {found} is newer than this software's "
                                      f"{head_revision()}: upgrade accelcal-rig")
                if found is None and not create:
                    registry._refuse_unmade()
                if found is None or (upgrade and found != head_revision()):
                    registry.upgrade()
                elif found != head_revision():
                    raise ConfigError(f"registry {described(url)}: schema {found} is older than this software's "
                                      f"{head_revision()}: a recording command (rig registry add, rig fit) upgrades it")
                registry._check_tables()
                return registry
            except sa.exc.OperationalError as exc:
                # SQLite answers "locked" at once, busy timeout or not, to a connection switching a new file
                # to WAL while another does: the other is done in a moment.
                if "locked" not in str(exc.orig) or attempt == _OPEN_ATTEMPTS - 1:
                    raise ConfigError(f"registry {described(url)}: cannot open: {_first_line(exc.orig)}") from None
                time.sleep(0.05 * (attempt + 1))
            except (sa.exc.SQLAlchemyError, CommandError) as exc:
                raise ConfigError(f"registry {described(url)}: {_first_line(getattr(exc, 'orig', None) or exc)}") from None
        raise AssertionError("unreachable")

    def _refuse_unmade(self) -> None:
        """A reader's database with no schema revision: empty (nothing recorded), or someone else's."""
        with self.engine.connect() as connection:
            _refuse_foreign(connection, self.url)
            if MigrationContext.configure(connection).get_current_revision() is None:
                raise ConfigError(f"registry {described(self.url)}: empty (nothing recorded in it yet)")

    def _check_tables(self) -> None:
        """Every table and column of the current schema is there (a table dropped or altered by hand is
        refused here in one line, not met as a failed query on some page)."""
        inspector = sa.inspect(self.engine)
        present = set(inspector.get_table_names())
        for table in registry_tables():
            if table.name not in present:
                raise ConfigError(f"registry {described(self.url)}: table {table.name} is missing: the database "
                                  "was damaged or changed by hand")
            columns = {c["name"] for c in inspector.get_columns(table.name)}
            lost = [c.name for c in table.columns if c.name not in columns]
            if lost:
                raise ConfigError(f"registry {described(self.url)}: table {table.name} lacks column "
                                  f"{', '.join(lost)}: the database was damaged or changed by hand")

    def upgrade(self, revision: str = "head") -> None:
        """Apply every migration not applied yet, one process at a time; never into someone else's database."""
        with self._migration_lock() as connection:
            _refuse_foreign(connection, self.url)
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
        """The ids of the entries of `batch` not registered before, inserted in one transaction with their
        figures."""
        dialect = self.engine.dialect.name
        insert = postgresql.insert(calibrations) if dialect == "postgresql" else sqlite.insert(calibrations)
        statement = insert.on_conflict_do_nothing(index_elements=["source_sha256", "serial", "fit_sha256"])
        rows = [{k: v for k, v in entry.items() if k != "figures"} for entry in batch]
        figures = {_identity(entry): entry.get("figures", []) for entry in batch}
        returning = statement.returning(calibrations.c.id, calibrations.c.source_sha256, calibrations.c.serial,
                                        calibrations.c.fit_sha256)
        for attempt in range(10):
            try:
                with self.engine.begin() as connection:
                    added = [(int(row.id), _identity(row._mapping)) for row in connection.execute(returning, rows)]
                    kept = [{**figure, "calibration_id": row_id} for row_id, key in added for figure in figures[key]]
                    if kept:
                        connection.execute(sa.insert(calibration_figures), kept)
                    return [row_id for row_id, _ in added]
            except sa.exc.OperationalError as exc:  # SQLite past its busy timeout; PostgreSQL a lost deadlock
                again = ("locked" in str(exc.orig) if dialect == "sqlite"
                         else getattr(exc.orig, "sqlstate", None) in ("40P01", "40001"))
                if not again or attempt == 9:
                    raise
                time.sleep(0.1 * (attempt + 1))
        raise AssertionError("unreachable")

    # ------------------------------------------------------------------ reading
    @reads
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
            return _with_figures(connection, [dict(row._mapping) for row in connection.execute(query)])

    @reads
    def calibration(self, row_id: int) -> dict[str, Any]:
        """One calibration's row with its stored fit and its figures."""
        with self.engine.connect() as connection:
            row = connection.execute(sa.select(calibrations).where(calibrations.c.id == row_id)).first()
            if row is None:
                raise ConfigError(f"registry {described(self.url)}: no calibration {row_id}")
            return _with_figures(connection, [dict(row._mapping)])[0]

    @reads
    def current(self, serial: str, simulated: bool = False, *, channel: str) -> dict[str, Any] | None:
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

    @reads
    def why_not_valid(self, serial: str, channel: str) -> str:
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

    @reads
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

    @reads
    def last_actions(self, ids: list[int]) -> dict[int, str]:
        """The latest approval action (approve, reject, reissue) recorded on each of these rows that has one."""
        if not ids:
            return {}
        query = (sa.select(approvals.c.calibration_id, approvals.c.action)
                 .where(approvals.c.calibration_id.in_(ids)).order_by(approvals.c.id))
        with self.engine.connect() as connection:
            return {int(i): str(action) for i, action in connection.execute(query)}

    @reads
    def channels(self, serial: str | None = None) -> list[str]:
        """Every channel with a calibration recorded (of one serial, if given), by name."""
        query = sa.select(calibrations.c.channel).distinct()
        if serial is not None:
            query = query.where(calibrations.c.serial == serial)
        with self.engine.connect() as connection:
            return sorted(connection.execute(query).scalars())

    @reads
    def parts(self) -> list[str]:
        """Every part with a calibration recorded."""
        with self.engine.connect() as connection:
            return sorted(connection.execute(sa.select(calibrations.c.part).distinct()).scalars())

    @reads
    def count(self) -> int:
        with self.engine.connect() as connection:
            return int(connection.execute(sa.select(sa.func.count()).select_from(calibrations)).scalar_one())

    @contextmanager
    def _migration_lock(self) -> Iterator[Connection]:
        """A connection whose one transaction holds the schema for this process alone from reading its
        revision to the last migration: PostgreSQL's transaction-level advisory lock (released with the
        transaction, whatever happens in it), SQLite's write lock (BEGIN IMMEDIATE)."""
        with self.engine.connect() as connection:
            if self.engine.dialect.name == "postgresql":
                with connection.begin():
                    connection.execute(sa.text("SET LOCAL lock_timeout = '120s'"))
                    connection.execute(sa.text("SELECT pg_advisory_xact_lock(:key)"), {"key": _MIGRATION_LOCK})
                    yield connection
            else:
                # One transaction around every migration, begun here: Alembic then takes it as the caller's
                # and commits nothing of its own. Left to itself on SQLite it commits after each migration,
                # and another process waiting for the lock reads the schema between two of them while this
                # one goes on with the migrations it planned before: both apply the next one.
                connection.info["begin"] = "BEGIN IMMEDIATE"  # see _engine's begin hook
                try:
                    with connection.begin():
                        yield connection
                finally:
                    connection.info.pop("begin", None)


def _identity(entry: Any) -> tuple[str, str, str]:
    """What identifies a calibration (its unique key)."""
    return str(entry["source_sha256"]), str(entry["serial"]), str(entry["fit_sha256"])


def _with_figures(connection: Connection, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Each row with its figures (`figures`: name → {label, unit, axes, value, expanded_u, trend, lot}), read in
    chunks of ids."""
    found: dict[int, dict[str, dict[str, Any]]] = {int(row["id"]): {} for row in rows}
    ids = list(found)
    for start in range(0, len(ids), _BATCH):
        query = (sa.select(calibration_figures).where(calibration_figures.c.calibration_id.in_(ids[start:start + _BATCH]))
                 .order_by(calibration_figures.c.id))
        for figure in connection.execute(query):
            values = figure._mapping
            found[int(values["calibration_id"])][str(values["name"])] = {
                key: values[key] for key in ("label", "unit", "axes", "value", "expanded_u", "trend", "lot")}
    return [{**row, "figures": found[int(row["id"])]} for row in rows]


def _engine(url: str, create: bool = True, read_only: bool = False, timeouts: RegistryTimeouts | None = None) -> Engine:
    timeouts = timeouts or RegistryTimeouts()
    if url.startswith("sqlite:///"):
        return _sqlite_engine(Path(url.removeprefix("sqlite:///")), create, read_only, timeouts.sqlite_busy_s)
    query = url.partition("?")[2]
    # libpq's own connect_timeout, when the URL gives one; else ours: a server that accepts and never
    # answers is one line within seconds, not a wait of minutes. A server that stops answering a connection
    # already made: TCP's user timeout (unacknowledged data) and keepalives (a silent peer).
    connect_args: dict[str, Any] = {} if "connect_timeout=" in query else {
        "connect_timeout": max(2, round(timeouts.connect_s)), "tcp_user_timeout": round(timeouts.connect_s * 1000),
        "keepalives": 1, "keepalives_idle": 5, "keepalives_interval": 2, "keepalives_count": 2}
    if timeouts.statement_s is not None and "options=" not in query:
        connect_args["options"] = f"-c statement_timeout={round(timeouts.statement_s * 1000)}"
    try:
        return sa.create_engine(url, pool_pre_ping=True, connect_args=connect_args,
                                pool_timeout=max(1.0, timeouts.connect_s))
    except (sa.exc.ArgumentError, ModuleNotFoundError) as exc:
        raise ConfigError(f"registry {described(url)}: {exc} (PostgreSQL needs: {install_hint('postgresql')})") from None


def _read_only_connection(path: Path, busy_s: float) -> sqlite3.Connection:
    """A reader's connection: read-only; immutable where SQLite cannot make its side files — a folder it cannot
    write (a read-only mount), or a full disk (its shared-memory file cannot be made: "disk I/O error" at the
    first read) when no write-ahead log holds anything the file does not (immutable reads would miss it)."""
    def connect(immutable: bool) -> sqlite3.Connection:
        address = f"file:{quote(str(path))}?mode=ro" + ("&immutable=1" if immutable else "")
        return sqlite3.connect(address, uri=True, timeout=busy_s, check_same_thread=False)

    if not os.access(path.parent, os.W_OK):
        return connect(True)
    connection = connect(False)
    try:
        connection.execute("SELECT count(*) FROM sqlite_master").fetchone()
        return connection
    except sqlite3.OperationalError as exc:
        connection.close()
        wal = path.with_name(path.name + "-wal")
        if "disk I/O error" not in str(exc) or (wal.exists() and wal.stat().st_size > 0):
            raise
        return connect(True)


def _sqlite_engine(path: Path, create: bool, read_only: bool, busy_s: float = _SQLITE_BUSY_S) -> Engine:
    """An SQLite registry: in WAL mode for the commands that write (readers never block the writer, nor it
    them); a reader's connection read-only, and on a mount where not even SQLite's side files can be made,
    opened as immutable (nothing can write there either)."""
    if create:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ConfigError(f"registry sqlite:///{path}: cannot create its folder: {exc}") from None
    if read_only:
        engine = sa.create_engine("sqlite://", poolclass=sa.pool.NullPool,
                                  creator=lambda: _read_only_connection(path, busy_s))
    else:
        engine = sa.create_engine(f"sqlite:///{path}", connect_args={"timeout": busy_s},
                                  poolclass=sa.pool.NullPool)

    @sa.event.listens_for(engine, "connect")
    def _pragmas(dbapi_connection: Any, _: Any) -> None:
        dbapi_connection.isolation_level = None  # SQLAlchemy's BEGIN, not pysqlite's own
        cursor = dbapi_connection.cursor()
        if not read_only and _ours_or_empty(cursor):
            cursor.execute("PRAGMA journal_mode=WAL")  # readers never block the writer, nor it them
        cursor.execute(f"PRAGMA busy_timeout={int(busy_s * 1000)}")
        cursor.execute("PRAGMA foreign_keys=ON")  # a decision names a calibration that exists
        cursor.close()

    @sa.event.listens_for(engine, "begin")
    def _begin(connection: Connection) -> None:
        connection.exec_driver_sql(connection.info.get("begin", "BEGIN"))
    return engine


def _refuse_foreign(connection: Connection, url: str) -> None:
    """Refuse a database with tables and no schema revision: it is someone else's (read under the migration
    lock, so that a registry another process is creating now is not taken for one)."""
    if MigrationContext.configure(connection).get_current_revision() is not None:
        return
    tables = sa.inspect(connection).get_table_names()
    if tables:
        shown = ", ".join(sorted(tables)[:4]) + (", …" if len(tables) > 4 else "")
        raise ConfigError(f"registry {described(url)}: not an accelcal-rig registry (it holds tables {shown} and no "
                          "schema revision); name another with --registry")


def _ours_or_empty(cursor: sqlite3.Cursor) -> bool:
    """Whether an SQLite file is a registry or nothing yet: someone else's database is not switched to WAL
    (opening it is refused; it must be left as it was)."""
    tables = {row[0] for row in cursor.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    return not tables or "alembic_version" in tables


def _first_line(error: object) -> str:
    return (str(error).strip().splitlines() or [type(error).__name__])[0]
