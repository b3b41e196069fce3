"""A gyroscope's calibration as its own row (channel `gyro`): its figures in °/s (bias at the reference
temperature and its expanded uncertainty at rest, the expanded uncertainty at the largest calibrated rate, the verification rate steps' RMS error),
and each channel's noise from the campaign's still record (angle or velocity random walk, bias instability).
Added as columns; for the calibrations already recorded (accelerometers, every one) the noise figures are
filled from each stored fit where it has them.

Revision ID: 0004
Revises: 0003
"""

import sqlalchemy as sa
from alembic import op

from accelcal_rig.registry.migrations.frozen_figures import noise_figures

revision = "0004"
down_revision = "0003"
branch_labels = None
depends_on = None

#: The columns added, and their types.
_ADDED = {"bias_dps": sa.JSON, "bias_uncertainty_dps": sa.JSON, "expanded_uncertainty_dps": sa.JSON, "verification_rmse_dps": sa.Float,
          "arw_deg_per_rthr": sa.JSON, "bias_instability_dph": sa.JSON, "vrw_m_s_per_rthr": sa.JSON,
          "bias_instability_ug": sa.JSON}
_FILLED = ("vrw_m_s_per_rthr", "bias_instability_ug")


def upgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name, kind in _ADDED.items():
            table.add_column(sa.Column(name, kind, nullable=True))
    rows = sa.table("calibrations", sa.column("id", sa.Integer), sa.column("channel", sa.String),
                    sa.column("calibration", sa.JSON), *(sa.column(name, _ADDED[name]) for name in _FILLED))
    connection = op.get_bind()
    ids = [row_id for (row_id,) in connection.execute(sa.select(rows.c.id).where(rows.c.channel == "accel")
                                                      .order_by(rows.c.id))]
    for start in range(0, len(ids), 500):  # a few hundred stored fits in memory at a time
        chunk = ids[start:start + 500]
        for row_id, calibration in connection.execute(sa.select(rows.c.id, rows.c.calibration)
                                                      .where(rows.c.id.in_(chunk))):
            figures = noise_figures(calibration)
            if any(figures[name] is not None for name in _FILLED):
                connection.execute(rows.update().where(rows.c.id == row_id)
                                   .values(**{name: figures[name] for name in _FILLED}))


def downgrade() -> None:
    with op.batch_alter_table("calibrations") as table:
        for name in _ADDED:
            table.drop_column(name)
