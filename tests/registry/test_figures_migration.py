"""Figures with their units (migration 0008): a registry the previous version wrote, holding an IMU's
accelerometer and gyroscope rows with the unit-suffixed columns of migrations 0002 and 0004, upgrades with every
figure as it was, and reads as the same calibrations recorded today do; the channel models state every figure
those columns held, value for value."""

from __future__ import annotations

import json
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest
import sqlalchemy as sa
import yaml

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import ChannelCalibration
from accelcal_rig.fit.channel_models import model_of
from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.location import normalised

DATA = Path(__file__).parents[1] / "data"
#: Each figure the columns of 0002 and 0004 held, by the name and unit it has now: (its column, its uncertainty's).
COLUMNS = {("bias", "mg"): ("bias_mg", "bias_uncertainty_mg"),
           ("scale_error", "ppm"): ("scale_error_ppm", "scale_uncertainty_ppm"),
           ("nonorthogonality", "mrad"): ("nonorthogonality_mrad", None),
           ("verification_rmse", "mg"): ("verification_rmse_mg", None),
           ("velocity_random_walk", "m/s/√h"): ("vrw_m_s_per_rthr", None),
           ("bias_instability", "µg"): ("bias_instability_ug", None),
           ("bias", "°/s"): ("bias_dps", "bias_uncertainty_dps"),
           ("expanded_uncertainty", "°/s"): ("expanded_uncertainty_dps", None),
           ("verification_rmse", "°/s"): ("verification_rmse_dps", None),
           ("angle_random_walk", "°/√h"): ("arw_deg_per_rthr", None),
           ("bias_instability", "°/h"): ("bias_instability_dph", None)}
TIMES = ("calibrated_at", "registered_at", "fitted_at")


def previous_rows() -> list[dict[str, Any]]:
    """The previous version's rows of IMU-A001, each with its stored fit (its channel's entry of the version-2
    calibration file that campaign's fit wrote)."""
    rows = json.loads((DATA / "registry-0007" / "imu-one-dut.rows.json").read_text())["rows"]
    calibration = yaml.safe_load((DATA / "calibration-v2" / "imu-one-dut.calibration.yaml").read_text())
    file = {k: calibration[k] for k in ("format", "format_version", "model", "created", "software_version", "source")}
    for row in rows:
        row["calibration"] = {"file": file, "sensor": calibration["duts"][row["serial"]]["channels"][row["channel"]]}
        for name in TIMES:
            row[name] = datetime.fromisoformat(row[name]) if row[name] else None
    return rows


def figures_of(row: dict[str, Any]) -> dict[tuple[str, str], tuple[Any, Any]]:
    """The figures a previous row's columns hold, by the name and unit each has now."""
    found = {}
    for key, (column, uncertainty) in COLUMNS.items():
        if row.get(column) is not None:
            found[key] = (row[column] if isinstance(row[column], list) else [row[column]],
                          row[uncertainty] if uncertainty else None)
    return found


def test_the_channel_models_state_every_figure_the_previous_version_recorded() -> None:
    for row in previous_rows():
        calibration = ChannelCalibration.model_validate(row["calibration"]["sensor"])
        stated = {(f.name, f.unit): (list(f.values), None if f.expanded is None else list(f.expanded))
                  for f in model_of(calibration).stored_figures(calibration)}
        assert stated == figures_of(row), row["channel"]


def test_a_registry_of_the_previous_schema_moves_every_figure_with_its_unit(registry_url: str) -> None:
    registry = Registry(_engine_of(registry_url), registry_url)
    registry.upgrade("0007")
    rows = previous_rows()
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    assert {"bias_mg", "bias_dps"} <= {c.name for c in table.columns}
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), rows)
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    columns = {c["name"] for c in sa.inspect(upgraded.engine).get_columns("calibrations")}
    assert not {column for pair in COLUMNS.values() for column in pair if column} & columns   # moved, not kept
    for previous in rows:
        row = upgraded.calibration(previous["id"])
        moved = {(name, f["unit"]): (f["value"], f["expanded_u"]) for name, f in row["figures"].items()}
        assert moved == figures_of(previous)                                          # every figure, exactly
        assert {f["axes"] for f in row["figures"].values()} <= {"xyz", ""}


def test_show_list_trend_and_stats_read_a_migrated_registry_as_the_same_calibrations_recorded_now(
        tmp_path: Path, capsys) -> None:
    """The previous rows migrated, and the same calibrations recorded today (their figures from the models):
    every command prints the same, in text and in JSON but for when each was recorded."""
    rows = previous_rows()
    migrated = normalised(str(tmp_path / "migrated.sqlite"))
    old = Registry(_engine_of(migrated), migrated)
    old.upgrade("0007")
    with old.engine.begin() as connection:
        connection.execute(sa.Table("calibrations", sa.MetaData(), autoload_with=old.engine).insert(), rows)
    Registry.open(migrated)
    recorded = normalised(str(tmp_path / "recorded.sqlite"))
    Registry.open(recorded).add([recorded_now(row) for row in sorted(rows, key=lambda r: r["id"])])
    commands = [["list", "--simulated"], ["show", "IMU-A001", "--simulated"], ["trend", "IMU-A001", "--simulated"],
                ["stats", "--part", "icm42688p", "--simulated"]]
    for command in commands:
        for form in ([], ["--json"]):
            outputs = []
            for url in (migrated, recorded):
                assert main(["registry", *command, *form, "--registry", url]) == 0, command
                outputs.append(capsys.readouterr().out)
            if form:
                outputs = [json.dumps(_without_times(json.loads(o)), sort_keys=True) for o in outputs]
            assert outputs[0] == outputs[1], command
            assert "IMU-A001" in outputs[0] or "icm42688p" in outputs[0]


def recorded_now(row: dict[str, Any]) -> dict[str, Any]:
    """A previous row as today's `registry.entries` records it: its figures from its channel's model."""
    calibration = ChannelCalibration.model_validate(row["calibration"]["sensor"])
    entry = {k: v for k, v in row.items() if k != "id" and not any(k in pair for pair in COLUMNS.values())}
    entry["figures"] = [{"name": f.name, "label": f.label, "unit": f.unit, "axes": "xyz" if len(f.values) == 3 else "",
                         "value": list(f.values), "expanded_u": None if f.expanded is None else list(f.expanded),
                         "trend": f.trend, "lot": f.lot} for f in model_of(calibration).stored_figures(calibration)]
    return entry


def _without_times(value: Any) -> Any:
    """JSON output without when each row was recorded (the two registries recorded them at other times)."""
    if isinstance(value, dict):
        return {k: _without_times(v) for k, v in value.items() if k != "registered_at"}
    if isinstance(value, list):
        return [_without_times(v) for v in value]
    return value


def _engine_of(url: str) -> sa.Engine:
    from accelcal_rig.registry.database import _engine

    return _engine(url)


@pytest.fixture(autouse=True)
def _no_lab_registry(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ACCELCAL_REGISTRY", raising=False)
