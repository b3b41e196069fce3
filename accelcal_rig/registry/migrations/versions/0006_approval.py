"""Approval: the lab's users and their roles, an append-only record of who approved, rejected or reissued
which calibration and when, and every certificate revision issued (its document kept, so an old revision
stays retrievable after a reissue). The database itself refuses to change or delete a recorded approval or
an issued revision (triggers on SQLite and PostgreSQL): the record is append-only whoever writes to it.

Revision ID: 0006
Revises: 0005
"""

import sqlalchemy as sa
from alembic import op

revision = "0006"
down_revision = "0005"
branch_labels = None
depends_on = None

_APPEND_ONLY = ("approvals", "certificate_revisions")
#: A calibration's identity and its fit: what a decision was about.
_IDENTITY = "id, serial, source_sha256, fit_sha256, calibrated_at, fitted_at, verdict, calibration"


def upgrade() -> None:
    op.create_table(
        "users",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("name", sa.String(64), nullable=False, unique=True),
        sa.Column("full_name", sa.String(128), nullable=False),
        sa.Column("role", sa.String(16), nullable=False),                 # approver | viewer
        sa.Column("password_hash", sa.String(256), nullable=True),        # argon2id; none: a reverse proxy's user
        sa.Column("disabled", sa.Boolean, nullable=False, server_default=sa.false()),
        sa.Column("created_at", sa.DateTime, nullable=False),
    )
    op.create_table(
        "approvals",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False, index=True),
        sa.Column("action", sa.String(16), nullable=False),               # approve | reject | reissue
        sa.Column("user_name", sa.String(64), nullable=False),
        sa.Column("full_name", sa.String(128), nullable=False),
        sa.Column("authority", sa.String(128), nullable=False),           # how the person was known
        sa.Column("reason", sa.Text, nullable=False, server_default=""),
        sa.Column("revision", sa.Integer, nullable=True),                 # the certificate revision it issued
        sa.Column("at", sa.DateTime, nullable=False),                     # UTC
    )
    op.create_table(
        "certificate_revisions",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False),
        sa.Column("revision", sa.Integer, nullable=False),
        sa.Column("number", sa.String(128), nullable=False),              # the certificate number it carries
        sa.Column("approver", sa.String(128), nullable=False),
        sa.Column("issued_at", sa.DateTime, nullable=False),              # UTC
        sa.Column("reason", sa.Text, nullable=False, server_default=""),  # a reissue's
        sa.Column("html", sa.Text, nullable=False),
        sa.Column("pdf", sa.LargeBinary, nullable=True),
        sa.Column("sha256", sa.String(64), nullable=False),               # of the PDF, else of the HTML
        sa.UniqueConstraint("calibration_id", "revision", name="one_certificate_per_revision"),
    )
    dialect = op.get_bind().dialect.name
    for table in _APPEND_ONLY:
        if dialect == "sqlite":
            for event in ("UPDATE", "DELETE"):
                op.execute(f"CREATE TRIGGER {table}_append_only_{event.lower()} BEFORE {event} ON {table} "
                           f"BEGIN SELECT RAISE(ABORT, '{table} is append-only'); END")
            # REPLACE deletes and inserts without firing a delete trigger: an insert over an existing id is refused
            op.execute(f"CREATE TRIGGER {table}_append_only_replace BEFORE INSERT ON {table} "
                       f"WHEN EXISTS (SELECT 1 FROM {table} WHERE id = NEW.id) "
                       f"BEGIN SELECT RAISE(ABORT, '{table} is append-only'); END")
        elif dialect == "postgresql":
            op.execute(f"CREATE FUNCTION {table}_append_only() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN "
                       f"RAISE EXCEPTION '{table} is append-only'; END $$")
            op.execute(f"CREATE TRIGGER {table}_append_only BEFORE UPDATE OR DELETE OR TRUNCATE ON {table} "
                       f"FOR EACH STATEMENT EXECUTE FUNCTION {table}_append_only()")
    # What was decided stays what it was: a calibration with a decision keeps its identity and its fit.
    decided = "EXISTS (SELECT 1 FROM approvals WHERE calibration_id = OLD.id)"
    if dialect == "sqlite":
        op.execute(f"CREATE TRIGGER calibrations_decided_update BEFORE UPDATE OF {_IDENTITY} ON calibrations "
                   f"WHEN {decided} BEGIN SELECT RAISE(ABORT, 'a decided calibration cannot change'); END")
        op.execute(f"CREATE TRIGGER calibrations_decided_delete BEFORE DELETE ON calibrations WHEN {decided} "
                   "BEGIN SELECT RAISE(ABORT, 'a decided calibration cannot change'); END")
    elif dialect == "postgresql":
        op.execute("CREATE FUNCTION calibrations_decided() RETURNS trigger LANGUAGE plpgsql AS $$ BEGIN "
                   f"IF {decided} THEN RAISE EXCEPTION 'a decided calibration cannot change'; END IF; "
                   "IF TG_OP = 'DELETE' THEN RETURN OLD; END IF; RETURN NEW; END $$")
        op.execute(f"CREATE TRIGGER calibrations_decided BEFORE UPDATE OF {_IDENTITY} OR DELETE ON calibrations "
                   "FOR EACH ROW EXECUTE FUNCTION calibrations_decided()")


def downgrade() -> None:
    dialect = op.get_bind().dialect.name
    if dialect == "sqlite":
        op.execute("DROP TRIGGER IF EXISTS calibrations_decided_update")
        op.execute("DROP TRIGGER IF EXISTS calibrations_decided_delete")
    elif dialect == "postgresql":
        op.execute("DROP TRIGGER IF EXISTS calibrations_decided ON calibrations")
        op.execute("DROP FUNCTION IF EXISTS calibrations_decided()")
    for table in _APPEND_ONLY:
        if dialect == "sqlite":
            for event in ("update", "delete", "replace"):
                op.execute(f"DROP TRIGGER IF EXISTS {table}_append_only_{event}")
        elif dialect == "postgresql":
            op.execute(f"DROP TRIGGER IF EXISTS {table}_append_only ON {table}")
            op.execute(f"DROP FUNCTION IF EXISTS {table}_append_only()")
    op.drop_table("certificate_revisions")
    op.drop_table("approvals")
    op.drop_table("users")
