"""The verdict column wide enough for CONDITIONAL (a limit met or missed inside its guard band under guarded
acceptance): String(8) → String(16). PASS and FAIL rows keep their verdicts; NOT JUDGED stays none (NULL).
A downgrade narrows it again only when no verdict is longer than 8 characters.

Revision ID: 0005
Revises: 0004
"""

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        table.alter_column("verdict", existing_type=sa.String(8), type_=sa.String(16), existing_nullable=True)


def downgrade() -> None:
    rows = sa.table("calibrations", sa.column("verdict", sa.String))
    longer = op.get_bind().execute(sa.select(sa.func.count()).select_from(rows)
                                   .where(sa.func.length(rows.c.verdict) > 8)).scalar_one()
    if longer:
        raise RuntimeError(f"{longer} calibrations have a verdict longer than 8 characters (CONDITIONAL): "
                           "schema 0004 cannot hold them")
    with op.batch_alter_table("calibrations") as table:
        table.alter_column("verdict", existing_type=sa.String(16), type_=sa.String(8), existing_nullable=True)
