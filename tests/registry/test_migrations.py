"""A lab upgrades without losing records: a database made by the first schema version, with calibrations
in it, is brought to the current one, and the figures the later versions add are filled from each stored fit
(migrations 0002 and 0004, as they computed them) and moved with their units (0008)."""

from __future__ import annotations

import pytest
import sqlalchemy as sa

from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.entries import campaign_entries
from accelcal_rig.registry.migrations.frozen_figures import reference_figures
from tests.registry.conftest import synthetic_entries


def of_schema(entries: list[dict], table: sa.Table) -> list[dict]:
    """Today's entries as a registry of an earlier schema held them: its columns only, the figures it had
    columns for in them (migration 0008 moved them out)."""
    from tests.registry.test_figures_migration import COLUMNS

    columns = {c.name for c in table.columns}
    rows = []
    for entry in entries:
        row = {k: v for k, v in entry.items() if k in columns}
        for figure in entry["figures"]:
            column, uncertainty = COLUMNS[(figure["name"], figure["unit"])]
            value = figure["value"] if figure["axes"] else figure["value"][0]
            row.update({column: value, **({uncertainty: figure["expanded_u"]} if uncertainty else {})})
        rows.append({k: v for k, v in row.items() if k in columns})
    return rows


def test_a_first_version_database_upgrades_with_its_records_and_their_figures(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry(_engine_of(registry_url), registry_url)
    registry.upgrade("0001")
    assert registry.revision() == "0001"
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    version_1 = of_schema([*campaign_entries(campaign, calibration),
                           *synthetic_entries(campaign_entries(campaign, calibration)[0], 3)], table)
    assert not {"fitted_at", "reference_c", "bias_mg"} & {c.name for c in table.columns}  # the first schema has none
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), version_1)
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    rows = upgraded.calibrations()
    assert len(rows) == 7
    for listed in rows:
        row = upgraded.calibration(listed["id"])
        expected = reference_figures(row["calibration"])
        figures = row["figures"]
        assert row["reference_c"] == expected["reference_c"]
        assert figures["bias"]["value"] == pytest.approx(expected["bias_mg"]) and figures["bias"]["unit"] == "mg"
        assert figures["scale_error"]["value"] == pytest.approx(expected["scale_error_ppm"])
        assert figures["bias"]["expanded_u"] == pytest.approx(expected["bias_uncertainty_mg"])
        assert figures["nonorthogonality"]["value"] == pytest.approx([expected["nonorthogonality_mrad"]])
        assert row["fitted_at"] is not None and row["fitted_at"].tzinfo is None
        assert row["channel"] == "accel"  # every calibration before channels: its DUT's accelerometer


def test_a_second_version_database_upgrades_and_its_calibrations_are_acceleration_channels(
        registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry(_engine_of(registry_url), registry_url)
    registry.upgrade("0002")
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    version_2 = of_schema(campaign_entries(campaign, calibration), table)
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
