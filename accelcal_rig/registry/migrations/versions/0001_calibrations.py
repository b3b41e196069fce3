"""The first schema: one row per calibration of one DUT, with the whole fit kept to export again.

Revision ID: 0001
Revises:
"""

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "calibrations",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("serial", sa.String(128), nullable=False),
        sa.Column("part", sa.String(64), nullable=False),
        sa.Column("source_kind", sa.String(16), nullable=False),
        sa.Column("source_path", sa.String(4096), nullable=False),
        sa.Column("source_sha256", sa.String(64), nullable=False),
        sa.Column("fit_sha256", sa.String(64), nullable=False),
        sa.Column("procedure", sa.String(128), nullable=False),
        sa.Column("rig", sa.String(128), nullable=False),
        sa.Column("simulated", sa.Boolean, nullable=False),
        sa.Column("software_version", sa.String(64), nullable=False),
        sa.Column("calibrated_at", sa.DateTime, nullable=False),
        sa.Column("registered_at", sa.DateTime, nullable=False),
        sa.Column("valid_from_c", sa.Float, nullable=False),
        sa.Column("valid_to_c", sa.Float, nullable=False),
        sa.Column("verdict", sa.String(8), nullable=True),
        sa.Column("verdict_reasons", sa.JSON, nullable=False),
        sa.Column("verification_rmse_mg", sa.Float, nullable=True),
        sa.Column("calibration", sa.JSON, nullable=False),
        sa.UniqueConstraint("source_sha256", "serial", "fit_sha256", name="one_calibration_per_fit"),
    )
    op.create_index("ix_calibrations_serial", "calibrations", ["serial"])
    op.create_index("ix_calibrations_calibrated_at", "calibrations", ["calibrated_at"])


def downgrade() -> None:
    op.drop_table("calibrations")
