"""Issuing as a lab does: each user's function (what a certificate prints under the approver's name: "Head of
laboratory"), and what a certificate revision amends (ISO/IEC 17025 §7.8.8: the customer, the contact, the date
of receipt, the condition, remarks), kept with the revision so the next one carries it over.

Revision ID: 0010
Revises: 0009
"""

import sqlalchemy as sa
from alembic import op

revision = "0010"
down_revision = "0009"
branch_labels = None
depends_on = None


def upgrade() -> None:
    # ALTER TABLE … ADD COLUMN (no table rebuilt): the append-only triggers on certificate_revisions stay.
    op.add_column("users", sa.Column("function", sa.String(128), nullable=False, server_default=""))
    op.add_column("certificate_revisions", sa.Column("amendments", sa.Text, nullable=False, server_default="{}"))


def downgrade() -> None:
    with op.batch_alter_table("certificate_revisions") as batch:
        batch.drop_column("amendments")
    with op.batch_alter_table("users") as batch:
        batch.drop_column("function")
