"""A lab upgrades without losing records: a database made by the first schema version, with calibrations
in it, is brought to the current one, and the figures the new version adds are filled from each stored fit."""

from __future__ import annotations

import pytest
import sqlalchemy as sa
from accelcal_rig.registry.figures import reference_figures

from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.entries import campaign_entries
from tests.registry.conftest import synthetic_entries

_ADDED_BY_0004 = ("bias_dps", "bias_uncertainty_dps", "expanded_uncertainty_dps", "verification_rmse_dps",
                  "arw_deg_per_rthr", "bias_instability_dph", "vrw_m_s_per_rthr", "bias_instability_ug")
_ADDED_BY_0003 = ("channel",)
_ADDED_BY_0002 = ("fitted_at", "reference_c", "bias_mg", "bias_uncertainty_mg", "scale_error_ppm", "scale_uncertainty_ppm",
                  "nonorthogonality_mrad")


def test_a_first_version_database_upgrades_with_its_records_and_their_figures(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry(_engine_of(registry_url), registry_url)
    registry.upgrade("0001")
    assert registry.revision() == "0001"
    version_1 = [{k: v for k, v in e.items() if k not in _ADDED_BY_0002 + _ADDED_BY_0003 + _ADDED_BY_0004}
                 for e in [*campaign_entries(campaign, calibration),
                           *synthetic_entries(campaign_entries(campaign, calibration)[0], 3)]]
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    assert not set(_ADDED_BY_0002) & {c.name for c in table.columns}  # the first schema has none of them
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), version_1)
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    rows = upgraded.calibrations()
    assert len(rows) == 7
    for listed in rows:
        row = upgraded.calibration(listed["id"])
        expected = reference_figures(row["calibration"])
        assert row["reference_c"] == expected["reference_c"]
        assert row["bias_mg"] == pytest.approx(expected["bias_mg"])
        assert row["scale_error_ppm"] == pytest.approx(expected["scale_error_ppm"])
        assert row["bias_uncertainty_mg"] == pytest.approx(expected["bias_uncertainty_mg"])
        assert row["fitted_at"] is not None and row["fitted_at"].tzinfo is None
        assert row["channel"] == "accel"  # every calibration before channels: its DUT's accelerometer


def test_a_second_version_database_upgrades_and_its_calibrations_are_acceleration_channels(
        registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry(_engine_of(registry_url), registry_url)
    registry.upgrade("0002")
    version_2 = [{k: v for k, v in e.items() if k not in _ADDED_BY_0003 + _ADDED_BY_0004}
                 for e in campaign_entries(campaign, calibration)]
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    assert "channel" not in {c.name for c in table.columns}
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), version_2)
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    rows = [upgraded.calibration(listed["id"]) for listed in upgraded.calibrations()]
    assert len(rows) == 4 and {row["channel"] for row in rows} == {"accel"}
    indexes = sa.inspect(upgraded.engine).get_indexes("calibrations")
    assert any(index["column_names"] == ["serial", "channel"] for index in indexes)


def _engine_of(url: str) -> sa.Engine:
    from accelcal_rig.registry.database import _engine

    return _engine(url)
