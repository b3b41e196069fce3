"""A magnetometer beside an accelerometer on one fixture (configs/sim-mixed.yaml's parts): the dry run drives the
LIS3MDL through its driver and bridge at its own rate and range, each pose records the site's field in the DUT's
frame, and the one pipeline calibrates, verifies, budgets, judges and compensates it by its channel model: the
hidden hard and soft iron recovered within their uncertainty, the verification RMSE at its expected fit RMSE.
Without the table's heading the field's direction is unknown: norm-only, its direction figures not stated."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import apply, load_calibration
from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.magnetic_field import MODEL as MAG_MODEL
from accelcal_rig.fit.sfem import distort
from accelcal_rig.sim.truth import mag_truth_for_serial
from accelcal_rig.store.read import load_campaign, read_vector_poses
from tests.conftest import REPO

MIXED_RIG = REPO / "configs" / "sim-mixed.yaml"
MAG, ACCEL = "LIS3MDL-M001", "ADX355-A001"
PROCEDURE = {
    "name": "mixed-small", "rig": "rig.yaml", "setpoints_c": [0, 20, 40, 60],
    "soak": {"criterion": "settling", "min_dwell_min": 10, "window_min": 10, "poll_s": 60},
    "schedule": {"kind": "paper-24"},
    "acquisition": {"samples_per_pose": 50, "range_g": 2, "odr_hz": 125, "settle_s": 1},
    "fit": {"mode": "reference", "polynomial_degree": 1},
    "verify": {"schedule": {"kind": "sphere", "count": 12}, "at_setpoints": True},
    "acceptance": {"decision_rule": "simple", "max_verification_rmse_mg": 1.0,
                   "mag": {"max_verification_rmse_mgauss": 2, "max_direction_error_deg": 0.5,
                           "parameters": {"at_c": 20, "bias_mgauss": 1000}}},
}


def mixed_rig(folder: Path, heading: bool = True) -> None:
    """configs/sim-mixed.yaml with one accelerometer and one magnetometer (without heading_deg: the field's
    direction unknown)."""
    config = yaml.safe_load(MIXED_RIG.read_text())
    sensors = config["fixture"]["sensors"]
    config["fixture"]["sensors"] = [sensors[0], next(s for s in sensors if s.get("part") == "lis3mdl")]
    if not heading:
        del config["heading_deg"]
    (folder / "rig.yaml").write_text(yaml.safe_dump(config, sort_keys=False))


def run_mixed(folder: Path, heading: bool = True, **changes: object) -> tuple[Path, Path]:
    mixed_rig(folder, heading)
    procedure = folder / "mixed.yaml"
    procedure.write_text(yaml.safe_dump({**PROCEDURE, **changes}, sort_keys=False))
    campaign = folder / "mixed.h5"
    run_campaign(prepare(procedure), campaign, dry_run=True, seed=4, overwrite=False)
    calibration = campaign.with_suffix(".calibration.yaml")
    fit_and_save(load_campaign(campaign), campaign, calibration, FitOptions(degree=1))
    return campaign, calibration


@pytest.fixture(scope="module")
def mixed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    folder = tmp_path_factory.mktemp("mixed")
    campaign, calibration = run_mixed(folder)
    _, report = fit_and_save(load_campaign(campaign), campaign, folder / "again.yaml", FitOptions(degree=1))
    return campaign, calibration, report


def test_each_part_runs_at_its_own_rate_and_range(mixed) -> None:
    campaign = load_campaign(mixed[0])
    duts = {d["serial"]: d for d in campaign.header.duts}
    assert (duts[ACCEL]["odr_hz"], duts[MAG]["odr_hz"]) == (125, 155)   # the LIS3MDL's next rate above 125 Hz
    info = campaign.channel_info(MAG, "mag")
    assert (info.quantity, info.unit, info.range, info.lsb) == ("magnetic field", "gauss", 4.0, 1 / 6842)
    assert [c.name for c in campaign.header.dut_channels(MAG)] == ["mag"]


def test_each_pose_records_the_site_field_in_the_duts_frame(mixed) -> None:
    campaign = load_campaign(mixed[0])
    poses = read_vector_poses(campaign, MAG, "mag")
    rig = yaml.safe_load(MIXED_RIG.read_text())["magnetic_field"]
    np.testing.assert_allclose(np.linalg.norm(poses.reference, axis=1), rig["total_intensity_nt"] / 1e5, rtol=1e-12)
    # The reference turns with the pose: 24 calibration poses see the field from as many directions.
    directions = poses.reference / np.linalg.norm(poses.reference, axis=1, keepdims=True)
    assert np.linalg.matrix_rank(directions) == 3 and np.min(directions @ directions.T) < -0.5


def test_the_magnetometer_is_calibrated_by_its_model_and_verified_at_its_expected_rmse(mixed) -> None:
    calibration = load_calibration(mixed[1])
    channel = calibration.channel(MAG, "mag")
    assert model_for_quantity("magnetic field") is MAG_MODEL
    assert (channel.model, channel.quantity, channel.unit, channel.mode) == ("sfem-eq1", "magnetic field", "gauss",
                                                                              "reference")
    figures = mixed[2][MAG]["channels"]["mag"]
    verification = figures["verification"]
    # Poses the fit never saw: as good as the fit expects, and no better than the noise allows.
    assert verification["rmse_mgauss"] <= 1.2 * figures["expected_fit_rmse_mgauss"]
    assert verification["rmse_mgauss"] >= 0.5 * verification["noise_floor_mgauss"]
    assert figures["rmse_before_mgauss"] > 50 * figures["rmse_after_mgauss"]   # hard iron of a few hundred mgauss
    assert "max_direction_error_deg" in verification and "max_tilt_error_deg" not in verification


def test_the_hidden_hard_and_soft_iron_are_recovered_within_their_uncertainty(mixed) -> None:
    figures = mixed[2][MAG]["channels"]["mag"]
    z = np.array([row["z"] for row in figures["truth_error"]])
    assert len(z) == 12 * 4 and np.mean(np.abs(z) < 3) >= 0.9 and np.max(np.abs(z)) < 5  # 12 parameters, 4 setpoints
    # The compensated reading of a field it never saw, at a temperature between the setpoints.
    channel = load_calibration(mixed[1]).channel(MAG, "mag")
    truth = mag_truth_for_serial(MAG).parameters_at(20.0)
    field = np.array([[0.2, -0.1, 0.4], [-0.3, 0.35, -0.05]])
    np.testing.assert_allclose(apply(channel, distort(field, truth), np.full(2, 20.0)), field, atol=1e-3)


def test_it_is_judged_budgeted_and_said_on_its_certificate_rows(mixed) -> None:
    report = mixed[2][MAG]
    assert report["verdict"] == "PASS", report["verdict_reasons"]
    limits = {row["limit_key"] for row in report["channels"]["mag"]["decision"]["limits"]}
    assert limits == {"mag.max_verification_rmse_mgauss", "mag.max_direction_error_deg", "mag.parameters.bias_mgauss"}
    budget = report["channels"]["mag"]["uncertainty_budget"]
    field_u = 20e-9 / 1e-4 / 0.488177                        # the rig's 20 nT of 48 818 nT, relative
    assert max(budget["sources_mgauss"]["field_intensity"]) == pytest.approx(1e3 * 0.488177 * field_u, rel=0.05)
    assert "gravity" not in budget["sources_mgauss"] and max(budget["expanded_mgauss"]) < 2
    assert mixed[2][ACCEL]["channels"]["accel"]["verdict"] == "PASS"


def test_without_the_tables_heading_it_is_fitted_norm_only_against_the_fields_size(tmp_path: Path) -> None:
    campaign, calibration = run_mixed(tmp_path, heading=False, setpoints_c=[20], schedule={"kind": "paper-24"},
                                      acceptance={}, verify={"schedule": {"kind": "sphere", "count": 6}})
    channel = load_calibration(calibration).channel(MAG, "mag")
    assert channel.mode == "norm-only"
    assert any("no table heading" in warning for warning in channel.warnings)
    _, report = fit_and_save(load_campaign(campaign), campaign, tmp_path / "again.yaml", FitOptions(degree=0))
    verification = report[MAG]["channels"]["mag"]["verification"]
    assert "max_direction_error_deg" not in verification and "rmse_mgauss" in verification
    # The accelerometer beside it keeps its reference fit.
    assert load_calibration(calibration).channel(ACCEL, "accel").mode == "reference"


def test_a_misspelt_magnetometer_limit_is_refused_before_anything_moves(tmp_path: Path) -> None:
    mixed_rig(tmp_path)
    procedure = tmp_path / "mixed.yaml"
    procedure.write_text(yaml.safe_dump({**PROCEDURE, "acceptance": {"mag": {"max_rmse_mgauss": 1}}}))
    with pytest.raises(ConfigError, match=r"acceptance\.mag\.max_rmse_mgauss: max_rmse_mgauss is not a figure "
                                          r"limit of the magnetometer model \(its: max_axis_error_mgauss"):
        prepare(procedure)


def test_the_c_header_compensates_the_magnetometer_as_apply_does(mixed, tmp_path: Path) -> None:
    """The header's magnetometer section, compiled: readings as gauss and as codes, inside and outside the
    calibrated range, give what `apply` gives."""
    import subprocess
    import warnings

    from accelcal_rig.export.c_header import to_c_header
    from accelcal_rig.fit.calibration import CalibrationRangeWarning, apply_codes
    from tests.export.test_c_header import PROGRAM, compiler

    calibration = load_calibration(mixed[1])
    channel = calibration.channel(MAG, "mag")
    header = to_c_header(calibration)
    assert "#define ACCELCAL_MAG_LIS3MDL_M001 0" in header and "accelcal_apply(" in header  # the ADXL355's too
    (tmp_path / "calibration.h").write_text(header)
    program = (PROGRAM.replace("accelcal_apply_codes(&ACCELCAL_SENSORS", "accelcal_apply_mag_codes(&ACCELCAL_MAGS")
               .replace("accelcal_apply(&ACCELCAL_SENSORS", "accelcal_apply_mag(&ACCELCAL_MAGS"))
    (tmp_path / "main.c").write_text(program)
    subprocess.run([compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "-o",
                    str(tmp_path / "mag"), str(tmp_path / "main.c"), "-lm"], check=True, capture_output=True)
    rng = np.random.default_rng(3)
    temperature = rng.uniform(-20.0, 80.0, 200)                      # calibrated 0…60 °C
    reading = rng.normal(0.0, 0.3, (200, 3))
    codes = rng.random(200) < 0.5
    reading[codes] = np.rint(reading[codes] / channel.lsb)
    stdin = "".join(f"0 {float(t)!r} {float(a)!r} {float(b)!r} {float(c)!r} {int(k)}\n"
                    for t, (a, b, c), k in zip(temperature, reading, codes))
    out = subprocess.run([str(tmp_path / "mag")], input=stdin, check=True, capture_output=True, text=True).stdout
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        expected = np.array([(apply_codes if k else apply)(channel, r, t) for t, r, k in zip(temperature, reading, codes)])
    assert np.max(np.abs(np.loadtxt(out.splitlines()) - expected)) < 1e-12   # gauss
    assert np.max(np.abs(expected - reading * np.where(codes, channel.lsb, 1.0)[:, None])) > 0.05  # hard iron off
