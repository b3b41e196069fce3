"""Figures with their units: each calibration's figures (bias, scale error, … and its noise) as rows of their
own, each with its name, unit, value per axis and expanded uncertainty, whatever quantity the calibration is
of; the unit-suffixed columns of migrations 0002 and 0004 (`bias_mg`, `bias_dps`, …) moved into them, every
value as it was, and dropped.

Revision ID: 0008
Revises: 0007
"""

import sqlalchemy as sa
from alembic import op

revision = "0008"
down_revision = "0007"
branch_labels = None
depends_on = None

#: Each figure column of 0002 and 0004 (and 0001's verification RMSE), its uncertainty column and what it moves
#: to: (name, label, unit, per axis, trend, lot).
_MOVED = {  # in the order each channel's model states its figures: bias, scale error, then the others
    "bias_mg": ("bias_uncertainty_mg", "bias", "bias", "mg", True, True, True),
    "bias_dps": ("bias_uncertainty_dps", "bias", "bias", "°/s", True, True, True),
    "scale_error_ppm": ("scale_uncertainty_ppm", "scale_error", "scale error", "ppm", True, True, True),
    "nonorthogonality_mrad": (None, "nonorthogonality", "non-orthogonality", "mrad", False, False, True),
    "expanded_uncertainty_dps": (None, "expanded_uncertainty", "expanded uncertainty at the largest rate", "°/s",
                                 True, False, False),
    "verification_rmse_mg": (None, "verification_rmse", "verification |g| RMSE", "mg", False, False, False),
    "verification_rmse_dps": (None, "verification_rmse", "verification rate RMS error", "°/s", False, False, True),
    "vrw_m_s_per_rthr": (None, "velocity_random_walk", "velocity random walk", "m/s/√h", True, False, False),
    "bias_instability_ug": (None, "bias_instability", "bias instability", "µg", True, False, False),
    "arw_deg_per_rthr": (None, "angle_random_walk", "angle random walk", "°/√h", True, False, True),
    "bias_instability_dph": (None, "bias_instability", "bias instability", "°/h", True, False, True),
}
_UNCERTAINTIES = ("bias_uncertainty_mg", "scale_uncertainty_ppm", "bias_uncertainty_dps")
_SCALARS = ("nonorthogonality_mrad", "verification_rmse_mg", "verification_rmse_dps")


def _figures_table() -> sa.TableClause:
    return sa.table("calibration_figures", sa.column("calibration_id", sa.Integer), sa.column("name", sa.String),
                    sa.column("label", sa.String), sa.column("unit", sa.String), sa.column("axes", sa.String),
                    sa.column("value", sa.JSON), sa.column("expanded_u", sa.JSON), sa.column("trend", sa.Boolean),
                    sa.column("lot", sa.Boolean))


def upgrade() -> None:
    op.create_table(
        "calibration_figures",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False, index=True),
        sa.Column("name", sa.String(64), nullable=False),
        sa.Column("label", sa.String(128), nullable=False),
        sa.Column("unit", sa.String(16), nullable=False),
        sa.Column("axes", sa.String(8), nullable=False),
        sa.Column("value", sa.JSON, nullable=False),
        sa.Column("expanded_u", sa.JSON, nullable=True),
        sa.Column("trend", sa.Boolean, nullable=False),
        sa.Column("lot", sa.Boolean, nullable=False),
        sa.UniqueConstraint("calibration_id", "name", name="one_figure_per_name"),
    )
    columns = [*_MOVED, *_UNCERTAINTIES]
    rows = sa.table("calibrations", sa.column("id", sa.Integer), *(sa.column(name, sa.JSON) for name in columns))
    figures = _figures_table()
    connection = op.get_bind()
    ids = [row_id for (row_id,) in connection.execute(sa.select(rows.c.id).order_by(rows.c.id))]
    for start in range(0, len(ids), 500):
        chunk = ids[start:start + 500]
        moved = []
        for row in connection.execute(sa.select(rows).where(rows.c.id.in_(chunk)).order_by(rows.c.id)):
            values = row._mapping
            for column, (uncertainty, name, label, unit, per_axis, trend, lot) in _MOVED.items():
                value = values[column]
                if value is None:
                    continue
                listed = [float(v) for v in value] if isinstance(value, list) else [float(value)]
                expanded = values[uncertainty] if uncertainty is not None else None
                moved.append({"calibration_id": values["id"], "name": name, "label": label, "unit": unit,
                              "axes": "xyz" if per_axis else "", "value": listed,
                              "expanded_u": [float(u) for u in expanded] if expanded is not None else None,
                              "trend": trend, "lot": lot})
        if moved:
            connection.execute(figures.insert(), moved)
    for name in columns:  # in place (SQLite ≥ 3.35 and PostgreSQL): rebuilding the table would break the keys
        op.execute(f"ALTER TABLE calibrations DROP COLUMN {name}")  # of the approvals and figures that name its rows


def downgrade() -> None:
    columns = [*_MOVED, *_UNCERTAINTIES]
    for name in columns:
        op.add_column("calibrations", sa.Column(name, sa.Float if name in _SCALARS else sa.JSON, nullable=True))
    rows = sa.table("calibrations", sa.column("id", sa.Integer), *(sa.column(name, sa.JSON) for name in columns))
    figures = _figures_table()
    by_figure = {(name, unit): (column, uncertainty) for column, (uncertainty, name, _, unit, *_) in _MOVED.items()}
    connection = op.get_bind()
    for row in connection.execute(sa.select(figures)).all():
        figure = row._mapping
        found = by_figure.get((figure["name"], figure["unit"]))
        if found is None:  # a quantity the earlier schema had no column for: kept only in the stored fit
            continue
        column, uncertainty = found
        value = figure["value"] if column not in _SCALARS else figure["value"][0]
        update = {column: value, **({uncertainty: figure["expanded_u"]} if uncertainty is not None else {})}
        connection.execute(rows.update().where(rows.c.id == figure["calibration_id"]).values(**update))
    op.drop_table("calibration_figures")
