"""Who may approve, and what was approved: the lab's users (a name, a role, a password stored as an argon2id
hash), the append-only record of every approval, rejection and reissue of a DUT's calibration, and the
certificate revision each approval issued (its document kept in the registry, so an earlier revision is
still there after a reissue).

A DUT's calibration from one source is one decision, whatever channels it has: an IMU's accelerometer and
gyroscope rows are approved together and share one certificate, kept under the DUT's first row (its lead).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any, Literal

import sqlalchemy as sa
from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError

from accelcal_rig.errors import ConfigError
from accelcal_rig.registry.database import Registry, reads
from accelcal_rig.registry.location import described
from accelcal_rig.registry.schema import approvals, calibrations, certificate_revisions, users
from accelcal_rig.registry.sign_ins import record_in

Action = Literal["approve", "reject", "reissue"]
Role = Literal["approver", "viewer"]
ROLES: tuple[Role, ...] = ("approver", "viewer")
#: A password shorter than this is refused (NIST SP 800-63B's minimum for a memorised secret).
MIN_PASSWORD = 8
_HASHER = PasswordHasher()
#: Who changed a user, in the sign-in record, when the command line did.
COMMAND_LINE = "command line"
#: Verified against when a name is unknown, so a wrong name costs as long as a wrong password.
_DUMMY_HASH = _HASHER.hash("accelcal-rig: no such user")


@dataclass(frozen=True)
class User:
    name: str
    full_name: str
    role: str
    disabled: bool
    #: Raised whenever every session of the user must end (registry/sign_ins.py).
    generation: int = 0
    #: What a certificate prints under their name as approver ("Head of laboratory"); "" when not stated.
    function: str = ""

    @property
    def may_approve(self) -> bool:
        return self.role == "approver" and not self.disabled


@dataclass(frozen=True)
class Decision:
    """Where a DUT's calibration stands: awaiting approval, approved (with its current certificate revision)
    or rejected, and by whom and when."""

    state: Literal["awaiting approval", "approved", "rejected"]
    revision: int | None = None
    by: str = ""
    at: datetime | None = None
    reason: str = ""


class Approvals:
    """The approval side of a registry (schema 0006 and later)."""

    def __init__(self, registry: Registry) -> None:
        self.registry = registry

    # ------------------------------------------------------------------ users
    def add_user(self, name: str, full_name: str, role: str, password: str | None, function: str = "") -> None:
        """A new user; `password` None for one a reverse proxy authenticates (no password here); `function`:
        what certificates print under their name as approver."""
        if role not in ROLES:
            raise ConfigError(f"role {role}: not one of {', '.join(ROLES)}")
        if not name or len(name) > 64 or not name.isprintable() or not full_name or len(full_name) > 128:
            raise ConfigError(f"user {name!r}: a name of 1–64 printable characters and a full name of 1–128 needed")
        hashed = None if password is None else _HASHER.hash(_checked(password))
        try:
            with self.registry.engine.begin() as connection:
                connection.execute(sa.insert(users).values(name=name, full_name=full_name, role=role,
                                                           password_hash=hashed, disabled=False,
                                                           created_at=utc_now_naive(), function=_function(function)))
        except sa.exc.IntegrityError:
            raise ConfigError(f"registry {described(self.registry.url)}: user {name} exists already") from None

    def set_password(self, name: str, password: str, client: str = COMMAND_LINE) -> None:
        """A new password: every session of the user ends."""
        self._change(name, {"password_hash": _HASHER.hash(_checked(password))}, client, "password changed")

    def set_disabled(self, name: str, disabled: bool, client: str = COMMAND_LINE) -> None:
        """Disabled: every session of the user ends. Enabled: a lockout (too many failed logins) ends too."""
        if disabled:
            self._change(name, {"disabled": True}, client, "disabled")
            return
        with self.registry.writing() as connection:
            row = connection.execute(sa.select(users.c.locked_until).where(users.c.name == name)).first()
            if row is None:
                raise ConfigError(f"registry {described(self.registry.url)}: no user {name}")
            connection.execute(sa.update(users).where(users.c.name == name)
                               .values(disabled=False, failed_logins=0, locked_until=None))
            if row.locked_until is not None:
                record_in(connection, utc_now_naive(), name, client, "unlocked",
                          f"enabled (it was locked until {row.locked_until:%Y-%m-%d %H:%M:%S}Z)")

    def set_role(self, name: str, role: str, client: str = COMMAND_LINE) -> None:
        """Another role: every session of the user ends (a session holds the rights of its login)."""
        if role not in ROLES:
            raise ConfigError(f"role {role}: not one of {', '.join(ROLES)}")
        self._change(name, {"role": role}, client, f"role changed to {role}")

    def set_function(self, name: str, function: str) -> None:
        """What certificates print under the user's name as approver from now on (issued ones keep theirs)."""
        self._update(name, function=_function(function))

    def _change(self, name: str, values: dict[str, Any], client: str, why: str) -> None:
        """A change to a user that ends every session of theirs, recorded with it, in one transaction."""
        now = utc_now_naive()
        with self.registry.writing() as connection:
            changed = connection.execute(sa.update(users).where(users.c.name == name).values(
                **values, session_generation=users.c.session_generation + 1)).rowcount
            if changed == 0:
                raise ConfigError(f"registry {described(self.registry.url)}: no user {name}")
            record_in(connection, now, name, client, "sessions ended", why)

    def _update(self, name: str, **values: Any) -> None:
        with self.registry.engine.begin() as connection:
            if connection.execute(sa.update(users).where(users.c.name == name).values(**values)).rowcount == 0:
                raise ConfigError(f"registry {described(self.registry.url)}: no user {name}")

    @reads
    def users(self) -> list[User]:
        with self.registry.engine.connect() as connection:
            rows = connection.execute(sa.select(users).order_by(users.c.name)).all()
        return [_user(r) for r in rows]

    @reads
    def user(self, name: str) -> User | None:
        with self.registry.engine.connect() as connection:
            row = connection.execute(sa.select(users).where(users.c.name == name)).first()
        return None if row is None else _user(row)

    @reads
    def authenticate(self, name: str, password: str) -> User | None:
        """The user whose password this is, not disabled; None otherwise (the same time either way)."""
        with self.registry.engine.connect() as connection:
            row = connection.execute(sa.select(users).where(users.c.name == name)).first()
        stored = row.password_hash if row is not None and row.password_hash else _DUMMY_HASH
        try:
            _HASHER.verify(stored, password)
        except (VerificationError, InvalidHashError):
            return None
        if row is None or not row.password_hash or row.disabled:
            return None
        if _HASHER.check_needs_rehash(stored):
            self._update(name, password_hash=_HASHER.hash(password))
        return _user(row)

    # ------------------------------------------------------------------ decisions
    @reads
    def rows_of(self, calibration_id: int) -> list[dict[str, Any]]:
        """The rows decided together with a calibration: its DUT's channels from the same fit of the same source
        (a refit is another calibration), lead first."""
        lead = self.registry.calibration(calibration_id)
        query = (sa.select(calibrations.c.id, calibrations.c.channel, calibrations.c.serial,
                           calibrations.c.simulated, calibrations.c.verdict)
                 .where(calibrations.c.source_sha256 == lead["source_sha256"],
                        calibrations.c.serial == lead["serial"],
                        calibrations.c.calibrated_at == lead["calibrated_at"],
                        _same(calibrations.c.fitted_at, lead["fitted_at"]))
                 .order_by(calibrations.c.id))
        with self.registry.engine.connect() as connection:
            return [dict(r._mapping) for r in connection.execute(query)]

    @reads
    def lead_id(self, calibration_id: int) -> int:
        return int(self.rows_of(calibration_id)[0]["id"])

    @reads
    def decision(self, calibration_id: int) -> Decision:
        """The latest decision on a DUT's calibration (its lead's record, in the order the database recorded
        them: each writer's clock may differ)."""
        lead = self.lead_id(calibration_id)
        with self.registry.engine.connect() as connection:
            events = _events(connection, lead)
        if not events:
            return Decision("awaiting approval")
        last = events[0]
        revision = next((e.revision for e in events if e.revision is not None), None)
        state: Literal["approved", "rejected"] = "rejected" if last.action == "reject" else "approved"
        return Decision(state, revision if state == "approved" else None, last.full_name, last.at, last.reason)

    @reads
    def decisions(self, calibration_ids: list[int]) -> dict[int, Decision]:
        return {i: self.decision(i) for i in calibration_ids}

    def record(self, calibration_id: int, action: Action, user: User, authority: str, reason: str = "",
               certificate: IssuedCertificate | None = None, at: datetime | None = None) -> int | None:
        """Record a decision on a DUT's calibration (every channel row of it), and the certificate revision an
        approval or a reissue issues, in one transaction; the revision number issued, if any. `at`: the time
        the certificate states (naive UTC; default now)."""
        if not user.may_approve:
            raise ConfigError(f"user {user.name} may not approve (role {user.role}"
                              f"{', disabled' if user.disabled else ''})")
        rows = self.rows_of(calibration_id)
        lead = int(rows[0]["id"])
        if action in ("reject", "reissue") and not reason.strip():
            raise ConfigError(f"calibration {lead}: a {action} needs a reason (--reason)")
        if action != "reject" and certificate is None:
            raise ConfigError(f"calibration {lead}: an {action} issues a certificate revision")
        if "\x00" in reason:
            raise ConfigError(f"calibration {lead}: a reason with a NUL character")
        try:
            with self.registry.engine.begin() as connection:
                return self._record(connection, rows, lead, action, user, authority, reason, certificate,
                                    at or utc_now_naive())
        except (sa.exc.IntegrityError, sa.exc.OperationalError) as exc:  # another decision in the same moment
            raise ConfigError(f"calibration {lead}: not recorded, another decision was being recorded at the same "
                              f"time ({str(exc.orig).splitlines()[0]}): look again and retry") from None

    def _record(self, connection: Any, rows: list[dict[str, Any]], lead: int, action: Action, user: User,
                authority: str, reason: str, certificate: IssuedCertificate | None, now: datetime) -> int | None:
        """The decision checked against the record as this transaction sees it, then recorded."""
        events = _events(connection, lead)
        state = "awaiting approval" if not events else "rejected" if events[0].action == "reject" else "approved"
        if action == "reissue" and state != "approved":
            raise ConfigError(f"calibration {lead}: {state}, so there is no certificate to reissue: approve it")
        if action == "approve" and state == "approved":
            raise ConfigError(f"calibration {lead}: approved already: a new revision is a reissue, with a reason")
        revision = None
        if certificate is not None and action != "reject":
            issued = connection.execute(sa.select(sa.func.max(certificate_revisions.c.revision))
                                        .where(certificate_revisions.c.calibration_id == lead)).scalar()
            revision = int(issued or 0) + 1
            if revision != certificate.revision:
                raise ConfigError(f"calibration {lead}: revision {certificate.revision} was rendered, but "
                                  f"{revision} is next (another approval at the same time?): try again")
            connection.execute(sa.insert(certificate_revisions).values(
                calibration_id=lead, revision=revision, number=certificate.number, approver=user.full_name,
                issued_at=now, reason=reason, html=certificate.html, pdf=certificate.pdf,
                sha256=hashlib.sha256(certificate.pdf or certificate.html.encode()).hexdigest(),
                amendments=json.dumps(certificate.amendments, sort_keys=True)))
        connection.execute(sa.insert(approvals), [
            {"calibration_id": int(r["id"]), "action": action, "user_name": user.name,
             "full_name": user.full_name, "authority": authority, "reason": reason,
             "revision": revision, "at": now} for r in rows])
        return revision

    @reads
    def next_revision(self, calibration_id: int) -> int:
        lead = self.lead_id(calibration_id)
        with self.registry.engine.connect() as connection:
            issued = connection.execute(sa.select(sa.func.max(certificate_revisions.c.revision))
                                        .where(certificate_revisions.c.calibration_id == lead)).scalar()
        return int(issued or 0) + 1

    @reads
    def trail(self, serial: str | None = None, calibration_id: int | None = None) -> list[dict[str, Any]]:
        """The record, oldest first: every decision (one per DUT, not per channel row) with who, how and when."""
        query = (sa.select(approvals, calibrations.c.serial, calibrations.c.channel)
                 .join(calibrations, calibrations.c.id == approvals.c.calibration_id)
                 .order_by(approvals.c.id))
        if serial is not None:
            query = query.where(calibrations.c.serial == serial)
        if calibration_id is not None:
            query = query.where(approvals.c.calibration_id == self.lead_id(calibration_id))
        with self.registry.engine.connect() as connection:
            rows = [dict(r._mapping) for r in connection.execute(query)]
        seen: set[tuple[Any, ...]] = set()
        out = []
        for row in rows:  # the channel rows of one decision share everything but their calibration id
            key = (row["serial"], row["action"], row["user_name"], row["at"], row["revision"])
            if key not in seen:
                seen.add(key)
                out.append(row)
        return out

    @reads
    def certificates(self, calibration_id: int) -> list[dict[str, Any]]:
        """Every revision issued for a DUT's calibration, without the documents."""
        lead = self.lead_id(calibration_id)
        listed = [c for c in certificate_revisions.columns if c.name not in ("html", "pdf")]
        with self.registry.engine.connect() as connection:
            return [dict(r._mapping) for r in connection.execute(
                sa.select(*listed).where(certificate_revisions.c.calibration_id == lead)
                .order_by(certificate_revisions.c.revision))]

    @reads
    def certificate(self, calibration_id: int, revision: int) -> dict[str, Any]:
        """One revision with its documents."""
        lead = self.lead_id(calibration_id)
        with self.registry.engine.connect() as connection:
            row = connection.execute(sa.select(certificate_revisions).where(
                certificate_revisions.c.calibration_id == lead, certificate_revisions.c.revision == revision)).first()
        if row is None:
            raise ConfigError(f"registry {described(self.registry.url)}: calibration {calibration_id} has no "
                              f"certificate revision {revision}")
        return dict(row._mapping)

    @reads
    def amendments(self, calibration_id: int) -> dict[str, str]:
        """What the DUT's newest certificate revision states in place of the campaign's facts (what a reissue
        carries over and amends further); {} before any revision."""
        lead = self.lead_id(calibration_id)
        with self.registry.engine.connect() as connection:
            stored = connection.execute(sa.select(certificate_revisions.c.amendments).where(
                certificate_revisions.c.calibration_id == lead).order_by(certificate_revisions.c.revision.desc())
                .limit(1)).scalar()
        try:
            found = json.loads(stored or "{}")
        except ValueError:
            found = {}
        return {str(k): str(v) for k, v in found.items()} if isinstance(found, dict) else {}

    @reads
    def approved_ids(self, calibration_ids: list[int]) -> set[int]:
        """Of these rows, those whose DUT's calibration is approved now."""
        return {i for i in calibration_ids if self.decision(i).state == "approved"}


@dataclass(frozen=True)
class IssuedCertificate:
    """A certificate revision rendered for an approval, to keep in the registry."""

    revision: int
    number: str
    html: str
    pdf: bytes | None
    #: The item facts this revision states in place of the campaign's (report/certificate.py AMENDABLE).
    amendments: dict[str, str] = field(default_factory=dict)


def _user(row: Any) -> User:
    return User(row.name, row.full_name, row.role, row.disabled, int(row.session_generation), row.function or "")


def _function(function: str) -> str:
    if len(function) > 128 or not function.isprintable():
        raise ConfigError(f"function {function[:40]!r}: one line of at most 128 characters")
    return function


def _events(connection: Any, lead: int) -> list[Any]:
    """A DUT calibration's decisions, newest first, in the order the database recorded them."""
    return list(connection.execute(sa.select(approvals).where(approvals.c.calibration_id == lead)
                                   .order_by(approvals.c.id.desc())).all())


def _same(column: Any, value: Any) -> Any:
    return column.is_(None) if value is None else column == value


def utc_now_naive() -> datetime:
    """Now in UTC, as the registry's DateTime columns hold it (naive, UTC by convention)."""
    return datetime.now(UTC).replace(tzinfo=None)


def _checked(password: str) -> str:
    if len(password) < MIN_PASSWORD:
        raise ConfigError(f"a password of at least {MIN_PASSWORD} characters is needed")
    return password
