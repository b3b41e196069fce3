"""Which channel of its DUT a calibration is (`accel`; an IMU's `gyro` once a channel model calibrates it):
every calibration recorded before is its DUT's acceleration channel.

Revision ID: 0003
Revises: 0002
"""

import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        table.add_column(sa.Column("channel", sa.String(16), nullable=False, server_default="accel"))
        table.create_index("calibrations_serial_channel", ["serial", "channel"])


def downgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        table.drop_index("calibrations_serial_channel")
        table.drop_column("channel")
