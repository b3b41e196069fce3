"""A six-axis IMU's gyroscope over temperature on the simulated rate table: the plan turns each fixture axis
both ways at every rate, the rig records the table's and the Earth's rate as the reference, and the fit
recovers each DUT's hidden model within its stated uncertainty, compensates rates it never saw, and reads
the noise record's Allan figures. Bad input gets one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
from accelcal_rig.assembly import run_campaign
from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.acceleration import accelerometer_poses
from accelcal_rig.fit.acceptance import judge
from accelcal_rig.fit.angular_rate import MODEL as GYRO_MODEL
from accelcal_rig.fit.angular_rate import specific_force_g
from accelcal_rig.fit.calibration import apply, load_calibration
from accelcal_rig.fit.campaign_fit import FitOptions, fit_and_save
from accelcal_rig.fit.gyro_fit import GyroRecords, fit_gyro, read_gyro_records, site_of
from accelcal_rig.handheld.recording import read_campaign_recording
from accelcal_rig.plan.steps import RateStep, StopRotation, VerifyRate
from accelcal_rig.sim.devices import build_simulated_rig
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO

RIG = REPO / "configs" / "sim-imu.yaml"


def gyro_records(campaign: Campaign, serial: str) -> GyroRecords:
    """The DUT's gyroscope records, the specific force beside them, as its channel model reads them."""
    return read_gyro_records(campaign, serial, "gyro", specific_force_g(campaign, serial))


PROCEDURE = {
    "name": "imu-small", "rig": str(RIG), "setpoints_c": [0, 20, 40],
    "soak": {"criterion": "settling", "min_dwell_min": 10, "window_min": 10, "poll_s": 60},
    "schedule": {"kind": "paper-24"},
    "acquisition": {"samples_per_pose": 100, "range_g": 2, "range_dps": 2000, "fine_ranges": {"gyro": 250},
                    "odr_hz": 100, "settle_s": 1},
    "rates": {"rates_dps": [10, 100, 500, 1000], "settle_s": 1, "verify_rates_dps": [30, 700]},
    "noise": {"duration_s": 20},
    "fit": {"mode": "reference", "polynomial_degree": 1},
    "verify": {"schedule": {"kind": "sphere", "count": 6}, "at_setpoints": False, "setpoints_c": [10, 30]},
    "acceptance": {"max_verification_rmse_mg": 1.0,
                   "gyro": {"max_verification_rmse_dps": 0.5, "max_rest_error_dps": 0.1,
                            "parameters": {"at_c": 20, "bias_dps": 1.0}}},
}
#: The rate limits' tests change only the rates.
NO_LIMITS = {"acceptance": {}}


def _procedure(folder: Path, **changes: object) -> Path:
    path = folder / "imu.yaml"
    path.write_text(yaml.safe_dump({**PROCEDURE, **changes}, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def campaign_path(imu_dry_run: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """This module's copy of the session's run of PROCEDURE (seed 3: tests/conftest.py's imu_dry_run)."""
    from tests.report.imu_campaign import copied

    return copied(imu_dry_run, tmp_path_factory.mktemp("imu"))[0]


@pytest.fixture(scope="module")
def fitted(campaign_path: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    output = tmp_path_factory.mktemp("fit") / "cal.yaml"
    _, report = fit_and_save(load_campaign(campaign_path), campaign_path, output, FitOptions(degree=1))
    return output, report


def test_the_plan_turns_each_fixture_axis_both_ways_at_every_rate(tmp_path: Path) -> None:
    plan = prepare(_procedure(tmp_path)).plan
    stage = plan.stages[0]
    turning = [s for s in stage.body if isinstance(s, RateStep) and not isinstance(s, VerifyRate)]
    assert sorted({(s.about, s.rate_dps) for s in turning}) == sorted(
        (axis, sign * rate) for axis in "xyz" for rate in (10, 100, 500, 1000) for sign in (-1, 1))
    assert [s for s in stage.body if isinstance(s, VerifyRate)] == []          # verified at 10 and 30 °C only
    assert sum(isinstance(s, StopRotation) for s in stage.body) == 3
    for step in turning:   # the pose puts "up" along the fixture axis the vertical rate axis turns about
        axis = "xyz".index(step.about)
        assert step.pose.gravity_fixture[axis] == pytest.approx(1.0)
        assert step.rate_fixture_dps[axis] == step.rate_dps
    checks = [s for stage in plan.stages if stage.setpoint_c == 10 for s in stage.body if isinstance(s, VerifyRate)]
    assert sorted({abs(s.rate_dps) for s in checks}) == [30, 700] and len(checks) == 12


def test_the_accelerometer_fit_sees_only_the_poses_taken_at_rest(campaign_path: Path) -> None:
    campaign = load_campaign(campaign_path)
    kinds = set(campaign.header.plan.kind)
    assert {"rate", "verify-rate", "noise"} <= kinds                            # stored as written, whole
    poses = accelerometer_poses(campaign, campaign.serials[0])
    assert len(poses.setpoint_c) == 3 * 24 + 2 * 6


def test_the_analyses_and_hand_held_readers_take_the_poses_at_rest_only(campaign_path: Path) -> None:
    """A rate step's turning table (centripetal acceleration) and a noise record are no static poses."""
    setpoint, duts, numbers = poses_at_setpoint(campaign_path, 20.0)
    assert setpoint == 20.0 and sorted(numbers.tolist()) == list(range(1, 25))
    assert all(len(poses.setpoint_c) == 24 for poses in duts.values())
    recording = read_campaign_recording(campaign_path, None, 20.0)
    assert len(recording.t_s) == 24 * PROCEDURE["acquisition"]["samples_per_pose"]


def test_every_gyroscope_reference_holds_the_table_and_the_earth(campaign_path: Path) -> None:
    campaign = load_campaign(campaign_path)
    records = gyro_records(campaign, campaign.serials[0])
    at_rest = records.rows("pose")
    earth = np.linalg.norm(records.reference_dps[at_rest], axis=1)
    assert earth == pytest.approx(np.degrees(7.292115e-5), rel=1e-6)   # latitude and heading given: all of it
    turning = records.rows("rate")
    assert np.sort(np.unique(np.round(np.abs(records.reference_dps[turning]).max(axis=1)))).tolist() == [10, 100, 500,
                                                                                                       1000]
    # At rest, in the noise records and at rates within 80 % of ±250 °/s the gyroscope was at its finer range.
    assert records.range_dps is not None
    fine = records.range_dps == 250.0
    slow = np.linalg.norm(records.reference_dps, axis=1) <= 200.0
    assert np.array_equal(fine, slow) and fine.any() and (~fine).any()


def test_the_fit_recovers_the_hidden_gyroscope_within_its_uncertainty(fitted: tuple[Path, dict]) -> None:
    _, report = fitted
    z = np.array([t["z"] for r in report.values() for t in r["channels"]["gyro"]["truth_error"]])
    assert len(z) == 4 * 3 * 27
    assert np.max(np.abs(z)) < 4.5                      # 324 values: 4.5σ is one in 3 × 10⁵ for each
    assert 0.6 < np.std(z) < 1.5                        # the quoted σ is the scatter, neither much more nor less
    for serial, dut in report.items():
        gyro = dut["channels"]["gyro"]
        assert gyro["rmse_after_dps"] < gyro["rmse_before_dps"] / 100, serial
        assert "latitude 48.14" in gyro["earth_rate"] and "heading 30" in gyro["earth_rate"]


def test_rates_the_fit_never_saw_are_compensated(fitted: tuple[Path, dict], campaign_path: Path) -> None:
    path, report = fitted
    calibration = load_calibration(path)
    campaign = load_campaign(campaign_path)
    for serial in campaign.serials:
        verification = report[serial]["channels"]["gyro"]["verification"]
        assert verification["rate_steps"] == 24
        assert verification["rmse_dps"] < verification["rmse_before_dps"] / 50
        # Compensated with the calibration file, as firmware would: the same figure.
        records = gyro_records(campaign, serial)
        assert records.range_dps is not None
        errors = []
        for range_dps in (250.0, 2000.0):  # 30 °/s at the finer range, 700 °/s at ±2000: each at its own range
            rows = records.rows("verify-rate") & (records.range_dps == range_dps)
            assert rows.any()
            rate = apply(calibration.channel(serial, "gyro"), records.mean_dps[rows], records.temperature_c[rows],
                         {"acceleration": records.force_g[rows]}, range_dps)
            errors.append(rate - records.reference_dps[rows])
        rms = float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))
        assert rms == pytest.approx(verification["rmse_dps"], rel=1e-6)
        assert calibration.duts[serial].not_calibrated == {}


def test_the_noise_record_gives_each_axis_its_random_walk(fitted: tuple[Path, dict], campaign_path: Path) -> None:
    """The simulated gyroscope's white noise and its 0.061 °/s codes: the angle random walk lies between the
    noise's alone and with the worst rounding (a code's quarter, squared); its bias instability (5 °/h) as far
    as a short record can tell it."""
    _, report = fitted
    campaign = load_campaign(campaign_path)
    bounds: list[float] = []
    for serial, dut in report.items():
        allan = dut["channels"]["gyro"]["allan"]
        truth = campaign.header.truth[serial]
        sigma, lsb = float(truth["gyro_noise_dps_per_sample"]), campaign.channel_info(serial, "gyro").lsb
        low, high = sigma / 10.0 * 60.0, np.sqrt(sigma**2 + lsb**2 / 4) / 10.0 * 60.0
        for axis in allan["arw_deg_per_rthr"]:
            assert axis["low"] < axis["value"] < axis["high"]
            assert 0.9 * low < axis["value"] < 1.1 * high
        assert allan["samples"] == 2000 and allan["gaps_share"] < 0.05 and allan["setpoint_c"] == 20
        assert len(allan["by_setpoint"]) == 3 and "vrw_m_s_per_rthr" in dut["channels"]["accel"]["allan"]
        for axis in allan["bias_instability_dph"]:   # a value with its interval, or 0 and an upper bound
            assert 0 <= axis["low"] <= axis["value"] <= axis["high"] and axis["high"] > 0
        bounds.extend(max(a["value"], a["high"]) for a in allan["bias_instability_dph"])
    # A 20 s record reads the bias instability at a few seconds, where the 5 °/h flicker floor barely shows
    # above the white noise: its upper ends lie about it, not orders away (12 axes: their median scatters by
    # a factor of two or so from one run's noise to another's).
    truth = campaign.header.truth[campaign.serials[0]]["gyro_bias_instability_dph"]
    assert truth == 5.0 and 0.5 * truth < float(np.median(bounds)) < 4 * truth


@pytest.mark.parametrize(("changes", "key", "message"), [
    ({"rates": {"rates_dps": [2500]}}, "rates", "not inside the gyroscope's range"),
    ({"rates": {"rates_dps": [1400, 1600]}, "acquisition": {**PROCEDURE["acquisition"], "range_dps": 2000}},
     "rates", "beyond turntable axis outer's max_rate_dps 1500"),
    ({"rates": {"rates_dps": [10], "verify_rates_dps": [10]}}, "rates", "is a calibration rate"),
    ({"rates": {"rates_dps": [1e-300]}}, "rates.rates_dps[0]", "greater than or equal to 0.1"),   # reads as rest
    ({"acquisition": {**PROCEDURE["acquisition"], "fine_ranges": {"gyro": 300}}}, "fine_ranges.gyro",
     "±300 dps is not a range of the ICM-42688-P"),
    ({"acquisition": {**PROCEDURE["acquisition"], "range_dps": 250, "fine_ranges": {"gyro": 500}}, "rates":
      {"rates_dps": [10], "settle_s": 1}}, "fine_ranges.gyro", "not finer than the channel's range"),
    ({"acquisition": {**PROCEDURE["acquisition"], "fine_ranges": {"accel": 4}}}, "fine_ranges.accel",
     "no accel channel that measures angular rate"),
])
def test_a_rate_the_part_or_the_table_cannot_take_is_one_line(tmp_path: Path, changes: dict, key: str,
                                                              message: str) -> None:
    with pytest.raises(ConfigError) as caught:
        prepare(_procedure(tmp_path, **NO_LIMITS, **changes))
    text = str(caught.value)
    assert message in text and key in text and "\n" not in text.strip()


def test_a_rate_step_on_a_table_without_a_rate_mode_is_one_line(tmp_path: Path) -> None:
    rig = yaml.safe_load(RIG.read_text())
    for axis in rig["turntable"]["axes"]:
        axis.pop("max_rate_dps", None)
        axis.pop("max_acceleration_dps2", None)
    (tmp_path / "rig.yaml").write_text(yaml.safe_dump(rig))
    with pytest.raises(ConfigError, match="no turntable axis has a rate mode") as caught:
        prepare(_procedure(tmp_path, rig=str(tmp_path / "rig.yaml")))
    assert "\n" not in str(caught.value).strip()


def test_rates_on_a_fixture_without_gyroscopes_are_one_line(tmp_path: Path) -> None:
    acquisition = {**PROCEDURE["acquisition"], "odr_hz": 125}   # an ADXL355's rate: only the gyroscope is missing
    with pytest.raises(ConfigError, match=r"rates: sensor ADX355-A001 of .*sim.yaml is an ADXL355, which has no gyroscope"):
        prepare(_procedure(tmp_path, rig=str(REPO / "configs" / "sim.yaml"), acquisition=acquisition))


def test_each_gyroscope_is_judged_against_its_limits(fitted: tuple[Path, dict], campaign_path: Path) -> None:
    path, report = fitted
    calibration = load_calibration(path)
    for serial, dut in report.items():
        assert dut["channels"]["gyro"]["verdict"] == "PASS" == calibration.channel(serial, "gyro").verdict
        assert any("verification rate RMS error" in r and "limit ≤ 0.5 °/s: pass" in r
                   for r in dut["channels"]["gyro"]["verdict_reasons"])
    # The same figures against limits they cannot meet: FAIL, each reason naming its figure.
    campaign = load_campaign(campaign_path)
    serial = campaign.serials[0]
    fit = fit_gyro(gyro_records(campaign, serial), 1, "clamp", site_of(campaign))
    assert fit.figures["verification"]["rmse_dps"] == report[serial]["channels"]["gyro"]["verification"]["rmse_dps"]
    tight = Acceptance.model_validate({"gyro": {"max_verification_rmse_dps": 1e-6, "max_scale_error_ppm": 1e-3,
                                                "parameters": {"at_c": 20, "gsens_dps_per_g": 1e-6}}})
    judged = judge(GYRO_MODEL, "gyro", fit, tight)
    assert judged.verdict == "FAIL" and len(judged.reasons) == 3
    assert any(r.startswith("g-sensitivity") and "limit ±1e-06 °/s/g: fail" in r for r in judged.reasons)
    # Each figure judged carries its own expanded uncertainty: the verification's from the table's rate
    # accuracy and the noise, each parameter's from the fit through its polynomial.
    assert all(c.expanded_u is not None and c.expanded_u > 0 for c in judged.checks)
    scale = next(c for c in judged.checks if c.limit_key == "gyro.max_scale_error_ppm")
    accuracy_ppm = 1e4 * site_of(campaign)["rate_accuracy_pct"] / np.sqrt(3)     # ± uniform, 1σ
    assert accuracy_ppm > 0 and scale.expanded_u >= 2 * accuracy_ppm


def test_the_budget_covers_the_truth_as_its_coverage_factor_says(fitted: tuple[Path, dict]) -> None:
    """Every DUT's verification axis errors against the simulation truth inside k = 2 about 95 % of the time
    (144 per DUT here, so a DUT's share scatters: the bench measures it over many seeds); the budget names its
    sources and grows with the rate."""
    _, report = fitted
    shares = [dut["channels"]["gyro"]["truth_coverage_k2"] for dut in report.values()]
    assert 0.85 <= float(np.mean(shares)) <= 1.0 and min(shares) >= 0.75
    for dut in report.values():
        budget = dut["channels"]["gyro"]["uncertainty_budget"]
        assert set(budget["at_largest_rate"]["sources_dps"]) == {"fit", "thermal model", "temperature", "table rate",
                                                                 "table pointing", "earth rate", "bias instability"}
        # The noise record's bias instability (or its upper bound) is how far a bias wanders: at rest, in the budget.
        assert budget["at_rest"]["sources_dps"]["bias instability"] == pytest.approx(dut["channels"]["gyro"]["bias_instability_1sigma_dps"])
        assert min(dut["channels"]["gyro"]["bias_instability_1sigma_dps"]) > 0
        assert budget["largest_rate_dps"] == 1000
        assert all(turning > resting for turning, resting in zip(budget["at_largest_rate"]["expanded_dps"],
                                                                 budget["at_rest"]["expanded_dps"]))
        assert dut["channels"]["gyro"]["expanded_uncertainty_dps"] == budget["at_largest_rate"]["expanded_dps"]
        assert budget["at_largest_rate"]["sources_dps"]["earth rate"] == [0.0, 0.0, 0.0]   # placed: taken out


def test_each_verification_axis_error_is_checked_against_the_uncertainty_the_certificate_states(
        fitted: tuple[Path, dict]) -> None:
    """The check a lab can repeat: each verification record's axis error against its reference, over the
    calibration's U (the budget's, at the record) combined with the verification measurement's (noise, the
    mean's quantisation, the reference): E_n ≤ 1 for about 95 %. The certificate states it beside the budget, and
    the dry run's truth check says which errors it counts."""
    path, report = fitted
    shares = []
    for dut in report.values():
        check = dut["channels"]["gyro"]["verification"]["consistency_k2"]
        assert check["axis_errors"] == 3 * (24 + 12)   # 24 verification rate steps and 12 poses, 3 axes each
        shares.append(check["within_share"])
    assert 0.85 <= float(np.mean(shares)) <= 1.0
    calibration = load_calibration(path)
    serial = next(iter(report))
    notes = GYRO_MODEL.sections(calibration.channel(serial, "gyro"))
    text = " ".join(note for section in notes for note in section.notes)
    assert "E_n ≤ 1 (ISO 13528)" in text and "the readings' noise taken out" in text


def test_a_table_left_turning_is_brought_to_rest_before_anything_moves(tmp_path: Path) -> None:
    """A run that finds the rate axis turning (a safe state that could not reach the table, a controller
    left turning by hand) holds it first, and says so."""
    turning: list[float] = []

    def left_turning(rig, procedure, clock, seed):
        instruments = build_simulated_rig(rig, procedure, clock, seed)
        instruments.turntable.rotate_at(0, 300.0, 500.0)           # type: ignore[attr-defined]
        clock.sleep(2.0)
        turning.append(instruments.turntable.read_rate_deg_s(0))  # type: ignore[attr-defined]
        return instruments

    small = {**PROCEDURE, "setpoints_c": [20], "rates": {"rates_dps": [10]}, "noise": None, "verify": None,
             "acceptance": {}, "fit": {"mode": "none"}, "schedule": {"kind": "six-position"}}
    path = tmp_path / "small.yaml"
    path.write_text(yaml.safe_dump({k: v for k, v in small.items() if v is not None}))
    run_campaign(prepare(path), tmp_path / "c.h5", dry_run=True, seed=1, overwrite=False,
                 build_instruments=left_turning)
    campaign = load_campaign(tmp_path / "c.h5")
    assert turning and abs(turning[0]) > 299
    warned = [e.message for e in campaign.events if e.kind == "preflight" and "turning at" in e.message]
    assert len(warned) == 1 and "brought to rest first" in warned[0]
    assert campaign.state == "done" and {"rate", "pose"} <= set(campaign.header.plan.kind)


def test_the_joint_thermal_fit_follows_a_drift_the_per_band_fit_blurs() -> None:
    """Records of a ramp: five bands whose records spread ±5 °C about the band's mean, from a truth whose bias
    drifts 0.5 °/s over the range. The per-band fit takes each band at its mean temperature and misses the drift
    within it; the joint fit (fit/gyro_joint.py) puts every record at its own temperature and recovers the truth
    to its noise."""
    from accelcal_rig.fit import gyro_model
    from accelcal_rig.fit.gyro_fit import fit_gyro_setpoint
    from accelcal_rig.fit.gyro_joint import fit_gyro_joint
    from accelcal_rig.fit.thermal import fit_thermal
    from accelcal_rig.sim.truth import gyro_truth_for_serial

    truth = gyro_truth_for_serial("IMU-J001")
    rng = np.random.default_rng(4)
    rates = [s * r * np.eye(3)[a] for a in range(3) for r in (10.0, 100.0, 1000.0) for s in (1, -1)]
    forces = [s * np.eye(3)[a] for a in range(3) for s in (1, -1)]
    design_rate = np.array(rates + [np.zeros(3)] * 6)
    design_force = np.array([np.array([0.0, 0.0, 1.0])] * 18 + forces)
    noise_dps = 1e-4
    temperature, rate, force, reading = [], [], [], []
    estimates, band_means = [], []
    for mean_c in (-40.0, -15.0, 10.0, 35.0, 60.0):
        t = mean_c + np.linspace(-5.0, 5.0, len(design_rate))
        read = gyro_model.distort_rate(design_rate, design_force, truth.parameters_at(t))
        read = read + rng.normal(0.0, noise_dps, read.shape)
        estimates.append(fit_gyro_setpoint(read, np.full_like(read, noise_dps), design_rate, design_force))
        band_means.append(t.mean())
        temperature.append(t), rate.append(design_rate), force.append(design_force), reading.append(read)
    temperature_c, rate_dps, force_g, mean_dps = (np.concatenate(v) for v in (temperature, rate, force, reading))
    start = fit_thermal(np.array(band_means), np.array([f.parameters for f in estimates]),
                        np.array([f.sigma for f in estimates]), np.ones(gyro_model.N_PARAMETERS, dtype=bool), 3)
    joint = fit_gyro_joint(start, temperature_c, mean_dps, np.full_like(mean_dps, noise_dps), rate_dps, force_g, 1e-5)
    assert joint.domain_c == (temperature_c.min(), temperature_c.max())   # fitted where the records are
    grid = np.linspace(-40.0, 60.0, 21)
    bias = slice(0, 3)

    def worst_bias_error(model) -> float:
        return float(np.max(np.abs(model.parameters_at(grid, "extrapolate")[:, bias] - truth.parameters_at(grid)[:, bias])))

    assert worst_bias_error(joint) < 2e-3                                # the truth's cubic, to its noise
    assert worst_bias_error(joint) < 0.5 * worst_bias_error(start)       # the per-band fit blurs the drift


def test_the_truth_keeps_each_records_bias_wander(campaign_path: Path) -> None:
    """A dry run keeps the wander each gyroscope record had (`simulation_truth/<serial>/gyro_wander_dps`): with it
    the truth explains the readings at rest and at slow rates to their noise (what a truth check of the
    calibration, whose U holds a reading's wander, must compare with); without it the wander is left over."""
    from accelcal_rig.fit import gyro_model
    from accelcal_rig.store.read import described_truth

    campaign = load_campaign(campaign_path)
    for serial in campaign.serials:
        records = gyro_records(campaign, serial)
        wander = campaign.truth_column(serial, "gyro_wander_dps")
        assert wander is not None and wander.shape == records.mean_dps.shape and np.isfinite(wander).all()
        scale = {float(r[0]): np.asarray(r[1:]) for r in campaign.header.truth[serial]["gyro_range_scale"]}[250.0]
        slow = (records.range_dps == 250.0) & (np.abs(records.reference_dps).max(axis=1) <= 60.0)
        truth = gyro_model.read_at_scale(described_truth(campaign, serial, "gyro"), 1.0 + scale)[slow]
        wandering = truth.copy()
        wandering[:, gyro_model.BIAS] += wander[slow]

        z_with, z_without = (_z_rms(records, slow, parameters) for parameters in (wandering, truth))
        assert z_with < 1.3 and z_without > 1.3 * z_with, (serial, z_with, z_without)


def _z_rms(records: GyroRecords, rows: np.ndarray, parameters: np.ndarray) -> float:
    """The RMS of the records' readings minus what `parameters` predict, each over its standard error."""
    from accelcal_rig.fit import gyro_model

    predicted = gyro_model.distort_rate(records.reference_dps[rows], records.force_g[rows], parameters)
    return float(np.sqrt(np.mean(((records.mean_dps[rows] - predicted) / records.stderr_dps[rows]) ** 2)))
