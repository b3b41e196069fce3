"""The registry records both sensors of an IMU: a row per calibrated channel, the gyroscope's with its own
figures (°/s) from its calibration; `add` twice records once; list, show, trend and stats name and filter
channels; a 0003 database holding records upgrades to 0004 with them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sqlalchemy as sa

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.entries import campaign_entries
from accelcal_rig.registry.migrations.frozen_figures import noise_figures
from tests.registry.test_migrations import of_schema
from tests.report.imu_campaign import copied

_ADDED_BY_0004 = ("bias_dps", "bias_uncertainty_dps", "expanded_uncertainty_dps", "verification_rmse_dps",
                  "arw_deg_per_rthr", "bias_instability_dph", "vrw_m_s_per_rthr", "bias_instability_ug")


@pytest.fixture(scope="module")
def imu(imu_dry_run: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    return copied(imu_dry_run, tmp_path_factory.mktemp("imu"))


def test_an_imu_is_recorded_as_a_row_per_channel_once(registry_url: str, imu: tuple[Path, Path]) -> None:
    campaign, calibration_path = imu
    registry = Registry.open(registry_url)
    added, already = registry.add(campaign_entries(campaign, calibration_path))
    assert len(added) == 8 and already == 0
    assert registry.add(campaign_entries(campaign, calibration_path)) == ([], 8)   # idempotent
    calibration = load_calibration(calibration_path)
    gyros = registry.calibrations(channel="gyro")
    assert sorted(r["serial"] for r in gyros) == sorted(calibration.of_quantity("angular rate")) and len(registry.calibrations()) == 8
    for row in gyros:
        gyro, figures = calibration.channel(row["serial"], "gyro"), row["figures"]
        assert row["verdict"] == gyro.verdict and {f["unit"] for f in figures.values()} == {"°/s", "ppm", "°/√h", "°/h"}
        assert figures["verification_rmse"]["value"] == pytest.approx([gyro.metrics["verification"]["rmse_dps"]])
        assert figures["expanded_uncertainty"]["value"] == pytest.approx(gyro.metrics["expanded_uncertainty_dps"])
        assert figures["bias"]["value"] == pytest.approx(gyro.parameters_at(row["reference_c"])[0:3].tolist())
        assert figures["scale_error"]["value"] == pytest.approx(
            ((gyro.parameters_at(row["reference_c"])[3:6] - 1) * 1e6).tolist())
        assert figures["angle_random_walk"]["value"] == pytest.approx(
            [e["value"] for e in gyro.metrics["allan"]["arw_deg_per_rthr"]])
        assert "bias_instability" in figures and "velocity_random_walk" not in figures
    for row in registry.calibrations(channel="accel"):
        sensor, figures = calibration.channel(row["serial"], "accel"), row["figures"]
        assert figures["bias"]["unit"] == "mg" and figures["verification_rmse"]["value"] == pytest.approx(
            [sensor.metrics["verification"]["rmse_mg"]])
        assert figures["velocity_random_walk"]["value"] == pytest.approx(
            [e["value"] for e in sensor.metrics["allan"]["vrw_m_s_per_rthr"]])
    valid = registry.current("IMU-A001", simulated=True, channel="gyro")
    assert valid is not None and valid["channel"] == "gyro"


def test_list_show_trend_stats_by_channel(imu: tuple[Path, Path], tmp_path: Path, capsys) -> None:
    campaign, calibration = imu
    registry = str(tmp_path / "lab.sqlite")
    assert main(["registry", "add", str(campaign), "--registry", registry]) == 0
    assert capsys.readouterr().out.strip() == f"{campaign}: 8 added"
    assert main(["registry", "add", str(campaign), "--registry", registry]) == 0
    assert capsys.readouterr().out.strip() == f"{campaign}: 0 added, 8 registered already"
    assert main(["registry", "list", "--channel", "gyro", "--json", "--registry", registry]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert len(listed) == 4 and {r["channel"] for r in listed} == {"gyro"}
    assert main(["registry", "list", "--registry", registry]) == 0
    table = capsys.readouterr().out.splitlines()
    assert "channel" in table[0] and sum(" gyro " in line for line in table) == 4 and sum(" accel " in line for line in table) == 4
    assert main(["registry", "show", "IMU-A001", "--simulated", "--registry", registry]) == 0
    shown = capsys.readouterr().out
    gyro = load_calibration(calibration).channel("IMU-A001", "gyro")
    assert shown.startswith("IMU-A001 accel (") and "valid calibration" in shown.splitlines()[0]
    assert "IMU-A001 gyro (" in shown
    assert f"verification rate RMS error {gyro.metrics['verification']['rmse_dps']:.5f} °/s" in shown
    assert "angle random walk " in shown and "history (2):" in shown
    assert main(["registry", "show", "IMU-A001", "--channel", "gyro", "--json", "--simulated", "--registry",
                 registry]) == 0
    shown_json = json.loads(capsys.readouterr().out)
    assert list(shown_json["current"]) == ["gyro"] and len(shown_json["history"]) == 1
    assert main(["registry", "trend", "IMU-A001", "--json", "--simulated", "--registry", registry]) == 0
    trend = json.loads(capsys.readouterr().out)["channels"]
    first = trend["gyro"]["calibrations"][0]
    assert list(trend) == ["accel", "gyro"] and first["figures"]["bias"]["value"] == pytest.approx(
        gyro.parameters_at(first["reference_c"])[0:3].tolist()) and first["figures"]["bias"]["unit"] == "°/s"
    assert trend["gyro"]["drift_per_year"]["bias"] is None  # one calibration: no drift yet
    part = listed[0]["part"]
    assert main(["registry", "stats", "--part", part, "--channel", "gyro", "--json", "--simulated",
                 "--registry", registry]) == 0
    stats = json.loads(capsys.readouterr().out)["channels"]
    assert list(stats) == ["gyro"] and stats["gyro"]["sensors"] == 4 and "angle_random_walk" in stats["gyro"]["distributions"]
    assert main(["registry", "stats", "--part", part, "--simulated", "--registry", registry]) == 0
    text = capsys.readouterr().out
    assert f"{part} accel: 4 sensors" in text and f"{part} gyro: 4 sensors" in text


def test_a_0003_database_with_records_upgrades_to_0004(registry_url: str, imu: tuple[Path, Path]) -> None:
    from accelcal_rig.registry.database import _engine

    campaign, calibration = imu
    registry = Registry(_engine(registry_url), registry_url)
    registry.upgrade("0003")
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    version_3 = of_schema([e for e in campaign_entries(campaign, calibration) if e["channel"] == "accel"], table)
    assert not set(_ADDED_BY_0004) & {c.name for c in table.columns}
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), version_3)
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    rows = [upgraded.calibration(listed["id"]) for listed in upgraded.calibrations()]
    assert len(rows) == 4 and {r["channel"] for r in rows} == {"accel"}
    for row in rows:  # the noise of the records already there, filled from their stored fits
        expected = noise_figures(row["calibration"])["vrw_m_s_per_rthr"]
        assert expected is not None and row["figures"]["velocity_random_walk"]["value"] == pytest.approx(expected)
        assert row["figures"]["bias"]["unit"] == "mg" and "angle_random_walk" not in row["figures"]
    # The gyroscopes then join them; the accelerometers already there are not recorded twice.
    added, already = upgraded.add(campaign_entries(campaign, calibration))
    assert len(added) == 4 and already == 4
    assert np.all([r["channel"] == "gyro" for r in upgraded.calibrations(channel="gyro")])
