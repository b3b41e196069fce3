"""Sign-ins: who logged in, who failed, who is locked out, and whose sessions ended — kept in the registry, so
every dashboard of a lab and the command line see the same lockout and the same record.

A user's sessions end together: each session carries the user's session generation as it was when they logged
in, and raising it (logout, a new password, disabled, another role) ends every one of them at its next request.
`ACCOUNT_FAILURES` failed logins in a row lock the account for `LOCKOUT_S`; `rig registry user enable` unlocks
it sooner. The record (`sign_ins`) is append-only by use: nothing here changes or deletes a row of it.
"""

from __future__ import annotations

from datetime import datetime, timedelta
from typing import Any

import sqlalchemy as sa

from accelcal_rig.registry.database import Registry, reads
from accelcal_rig.registry.schema import sign_ins, users

#: Failed logins in a row that lock an account, and for how long.
ACCOUNT_FAILURES = 5
LOCKOUT_S = 15 * 60
#: What the record keeps of a name or a client address a request gave (a longer one is cut).
_NAME_CHARS = 64
EVENTS = ("login", "login failed", "locked", "unlocked", "logout", "sessions ended")


class SignIns:
    """The sign-in side of a registry (schema 0009 and later). `now`: naive UTC, as the registry keeps time."""

    def __init__(self, registry: Registry) -> None:
        self.registry = registry

    @reads
    def locked_for_s(self, name: str, now: datetime) -> float:
        """How much longer the account is locked out (0: it is not, or there is no such user)."""
        with self.registry.engine.connect() as connection:
            until = connection.execute(sa.select(users.c.locked_until).where(users.c.name == name)).scalar()
        return max(0.0, (until - now).total_seconds()) if until is not None else 0.0

    def failed(self, name: str, client: str, now: datetime, detail: str = "") -> float:
        """A failed login, recorded; the account (if it is one) locked once it has failed ACCOUNT_FAILURES times
        in a row. The lockout's length in seconds if this failure locked it, else 0."""
        with self.registry.writing() as connection:
            row = connection.execute(sa.select(users.c.failed_logins).where(users.c.name == name)).first()
            _record(connection, now, name, client, "login failed", detail)
            if row is None:
                return 0.0
            failures = int(row.failed_logins) + 1
            values: dict[str, Any] = {"failed_logins": failures}
            locked = failures >= ACCOUNT_FAILURES
            if locked:
                values = {"failed_logins": 0, "locked_until": now + timedelta(seconds=LOCKOUT_S)}
                _record(connection, now, name, client, "locked",
                        f"{failures} failed logins in a row: locked for {LOCKOUT_S // 60} min")
            connection.execute(sa.update(users).where(users.c.name == name).values(**values))
        return float(LOCKOUT_S) if locked else 0.0

    def signed_in(self, name: str, client: str, now: datetime) -> None:
        """A login: the failures and a lockout (ended, or it would not be) before it forgotten, recorded."""
        with self.registry.writing() as connection:
            connection.execute(sa.update(users).where(users.c.name == name).values(failed_logins=0, locked_until=None))
            _record(connection, now, name, client, "login")

    def end_sessions(self, name: str, client: str, now: datetime, event: str, detail: str = "") -> None:
        """Every session of the user ended (their generation raised), recorded as `event`."""
        with self.registry.writing() as connection:
            connection.execute(sa.update(users).where(users.c.name == name)
                               .values(session_generation=users.c.session_generation + 1))
            _record(connection, now, name, client, event, detail)

    @reads
    def generation(self, name: str) -> int | None:
        """The user's session generation (None: no such user)."""
        with self.registry.engine.connect() as connection:
            found = connection.execute(sa.select(users.c.session_generation).where(users.c.name == name)).scalar()
        return None if found is None else int(found)

    @reads
    def record(self, name: str | None = None, limit: int = 1000) -> list[dict[str, Any]]:
        """The newest `limit` sign-in events (of one user, if named), oldest first."""
        query = sa.select(sign_ins).order_by(sign_ins.c.id.desc()).limit(limit)
        if name is not None:
            query = query.where(sign_ins.c.user_name == name)
        with self.registry.engine.connect() as connection:
            return [dict(r._mapping) for r in reversed(connection.execute(query).all())]


def record_in(connection: Any, now: datetime, name: str, client: str, event: str, detail: str = "") -> None:
    """One event in the record, inside the caller's transaction (a change to a user and its record together)."""
    _record(connection, now, name, client, event, detail)


def _record(connection: Any, now: datetime, name: str, client: str, event: str, detail: str = "") -> None:
    assert event in EVENTS, event
    connection.execute(sa.insert(sign_ins).values(at=now, user_name=_printable(name), client=_printable(client),
                                                  event=event, detail=detail))


def _printable(text: str) -> str:
    """A name or an address as the record keeps it: printable, cut to what the column holds."""
    return "".join(c if c.isprintable() else "?" for c in text)[:_NAME_CHARS]
