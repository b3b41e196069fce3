"""Live status: what each running campaign publishes while it runs (its latest snapshot, its events, its
temperatures), so that one dashboard shows every rig of a lab; and a lot field on each calibration (what the
lab calls a lot, not the part number).

Revision ID: 0007
Revises: 0006
"""

import sqlalchemy as sa
from alembic import op

revision = "0007"
down_revision = "0006"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "live_campaigns",
        sa.Column("key", sa.String(64), primary_key=True),
        sa.Column("rig", sa.String(128), nullable=False),
        sa.Column("host", sa.String(255), nullable=False),
        sa.Column("campaign", sa.String(4096), nullable=False),
        sa.Column("procedure", sa.String(128), nullable=False),
        sa.Column("dry_run", sa.Boolean, nullable=False),
        sa.Column("pid", sa.Integer, nullable=False),
        sa.Column("state", sa.String(16), nullable=False),
        sa.Column("phase", sa.String(32), nullable=False),
        sa.Column("setpoint_c", sa.Float, nullable=True),
        sa.Column("setpoint_number", sa.Integer, nullable=False),
        sa.Column("setpoints_total", sa.Integer, nullable=False),
        sa.Column("poses_done", sa.Integer, nullable=False),
        sa.Column("poses_total", sa.Integer, nullable=False),
        sa.Column("chamber_c", sa.Float, nullable=True),
        sa.Column("dut_c", sa.JSON, nullable=False),
        sa.Column("remaining_s", sa.Float, nullable=True),
        sa.Column("clock_s", sa.Float, nullable=False),
        sa.Column("line", sa.Text, nullable=False),
        sa.Column("warnings", sa.Integer, nullable=False),
        sa.Column("errors", sa.Integer, nullable=False),
        sa.Column("verdicts", sa.JSON, nullable=False),
        sa.Column("findings", sa.JSON, nullable=False),
        sa.Column("abort_reason", sa.Text, nullable=False),
        sa.Column("started_at", sa.DateTime, nullable=False),
        sa.Column("updated_at", sa.DateTime, nullable=False, index=True),
    )
    op.create_table(
        "live_events",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("key", sa.String(64), nullable=False, index=True),
        sa.Column("clock_s", sa.Float, nullable=False),
        sa.Column("at", sa.DateTime, nullable=False),
        sa.Column("level", sa.String(16), nullable=False),
        sa.Column("kind", sa.String(32), nullable=False),
        sa.Column("message", sa.Text, nullable=False),
    )
    op.create_table(
        "live_temperatures",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("key", sa.String(64), nullable=False, index=True),
        sa.Column("clock_s", sa.Float, nullable=False),
        sa.Column("chamber_c", sa.Float, nullable=True),
        sa.Column("dut_c", sa.Float, nullable=True),
    )
    with op.batch_alter_table("calibrations") as batch:
        batch.add_column(sa.Column("lot", sa.String(64), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("calibrations") as batch:
        batch.drop_column("lot")
    for table in ("live_temperatures", "live_events", "live_campaigns"):
        op.drop_table(table)
