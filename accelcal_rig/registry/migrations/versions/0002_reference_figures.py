"""When a fit was made (beside when its sensor was measured), and the figures a lab queries across
calibrations (trend, lot statistics) at the reference temperature: added as columns and filled, for the
calibrations already recorded, from each one's stored fit.

Revision ID: 0002
Revises: 0001
"""

from datetime import UTC, datetime

import sqlalchemy as sa
from alembic import op

from accelcal_rig.registry.migrations.frozen_figures import reference_figures

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None

#: The columns added, and their types.
_ADDED = {"fitted_at": sa.DateTime, "reference_c": sa.Float, "bias_mg": sa.JSON, "bias_uncertainty_mg": sa.JSON, "scale_error_ppm": sa.JSON,
          "scale_uncertainty_ppm": sa.JSON, "nonorthogonality_mrad": sa.Float}


def upgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name, kind in _ADDED.items():
            table.add_column(sa.Column(name, kind, nullable=True))
    rows = sa.table("calibrations", sa.column("id", sa.Integer), sa.column("calibration", sa.JSON),
                    *(sa.column(name, kind) for name, kind in _ADDED.items()))
    connection = op.get_bind()
    ids = [row_id for (row_id,) in connection.execute(sa.select(rows.c.id).order_by(rows.c.id))]
    for start in range(0, len(ids), 500):  # a few hundred stored fits in memory at a time
        chunk = ids[start:start + 500]
        for row_id, calibration in connection.execute(sa.select(rows.c.id, rows.c.calibration)
                                                      .where(rows.c.id.in_(chunk))):
            connection.execute(rows.update().where(rows.c.id == row_id).values(**_filled(calibration)))


def _filled(calibration: dict) -> dict:
    """This migration's columns, from the stored fit (only these: later figures belong to later migrations)."""
    figures = reference_figures(calibration)
    created = datetime.fromisoformat(calibration["file"]["created"])
    fitted = (created.astimezone(UTC) if created.tzinfo else created).replace(tzinfo=None)
    return {"fitted_at": fitted, **{name: figures[name] for name in _ADDED if name != "fitted_at"}}


def downgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name in _ADDED:
            table.drop_column(name)
