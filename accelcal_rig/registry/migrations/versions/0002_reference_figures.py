"""The figures a lab queries across calibrations (trend, lot statistics), at the reference temperature:
added as columns and filled, for the calibrations already recorded, from each one's stored fit.

Revision ID: 0002
Revises: 0001
"""

import sqlalchemy as sa
from alembic import op

from accelcal_rig.registry.figures import reference_figures

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None

#: The columns added, and their types.
_ADDED = {"reference_c": sa.Float, "bias_mg": sa.JSON, "bias_uncertainty_mg": sa.JSON, "scale_error_ppm": sa.JSON,
          "scale_uncertainty_ppm": sa.JSON, "nonorthogonality_mrad": sa.Float}


def upgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name, kind in _ADDED.items():
            table.add_column(sa.Column(name, kind, nullable=True))
    rows = sa.table("calibrations", sa.column("id", sa.Integer), sa.column("calibration", sa.JSON),
                    *(sa.column(name, kind) for name, kind in _ADDED.items()))
    connection = op.get_bind()
    for row_id, calibration in connection.execute(sa.select(rows.c.id, rows.c.calibration)).all():
        connection.execute(rows.update().where(rows.c.id == row_id).values(**reference_figures(calibration)))


def downgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name in _ADDED:
            table.drop_column(name)
