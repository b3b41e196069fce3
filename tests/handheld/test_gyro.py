"""Hand-held gyroscope calibration: a known bias and K (1 % scale errors, 0.5 % cross terms) recovered from
a synthetic recording within the fit's own 3σ; recordings whose moves do not determine K refused in one
line; the real imucal session compared with imucal's published gyro calibration where it can be."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from accelcal_rig.cli import main
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import apply, load_calibration
from accelcal_rig.fit.sfem import distort, norm_only_gauge
from accelcal_rig.handheld.calibrate import fit_recording
from accelcal_rig.handheld.gyro import EARTH_RATE_DPS, fit_handheld_gyro, still_gyro_bias
from accelcal_rig.handheld.recording import CsvLayout, read_csv_recording
from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals
from accelcal_rig.sim.truth import truth_for_serial
from tests.conftest import REPO

#: raw_dps = K·ω + bias: scale errors about 1 %, cross terms about 0.5 %, a bias of a few tenths of °/s.
TRUE_MATRIX = np.array([[1.012, 0.004, -0.006],
                        [-0.005, 0.991, 0.003],
                        [0.006, -0.004, 1.008]])
TRUE_BIAS_DPS = np.array([0.31, -0.22, 0.17])
COLUMNS = "time_s,ax,ay,az,temp_c"
GYRO_COLUMNS = "gx,gy,gz"


@dataclass(frozen=True)
class GyroSession:
    t_s: np.ndarray          # (n,)
    accel_g: np.ndarray      # (n, 3) raw accelerometer, g
    gyro_dps: np.ndarray     # (n, 3) raw gyro, °/s
    accel_truth: np.ndarray  # (12,) Eq. 1 parameters, already in the norm-only gauge (so its frame is the body's)

    def write(self, path: Path, gyro_scale: float = 1.0) -> Path:
        data = np.column_stack([self.t_s, self.accel_g, np.full(len(self.t_s), 25.0), self.gyro_dps * gyro_scale])
        np.savetxt(path, data, delimiter=",", header=f"{COLUMNS},{GYRO_COLUMNS}", comments="", fmt="%.8f")
        return path


def _attitude(up_in_sensor: np.ndarray, heading_deg: float) -> Rotation:
    """Sensor → world attitude in which world-up reads `up_in_sensor`, at a heading."""
    align, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [up_in_sensor])
    return Rotation.from_euler("z", heading_deg, degrees=True) * align


def gyro_session(rng: np.random.Generator, *, poses: int = 16, rate_hz: float = 200.0, about_gravity_only: bool = False,
                 still_gyro: bool = False, gyro_noise_dps: float = 0.05, accel_noise_g: float = 2e-4,
                 gsens_dps_per_g: np.ndarray | None = None) -> GyroSession:
    """Still poses joined by smooth (minimum-jerk) turns along the shortest rotation between them: every face
    up and down, tilted as a hand puts it, then random ones, each at a random heading, so the turns are about
    many axes, few about the vertical. `about_gravity_only`: one face up throughout, only the heading changes
    (every turn about the vertical). `still_gyro`: the gyro columns read bias and noise only, as if spliced from
    another recording. `gsens_dps_per_g`: the gyro also reads G·f, f the specific force (g)."""
    faces = np.array([[0, 0, 1], [1, 0, 0], [0, -1, 0], [0, 0, -1], [-1, 0, 0], [0, 1, 0]], dtype=float)
    if about_gravity_only:
        ups = np.tile([0.2, -0.1, 1.0], (poses, 1))
    else:
        tilts = Rotation.from_rotvec(rng.normal(size=(poses, 3)) * np.radians(15.0) / np.sqrt(3))
        ups = tilts.apply(np.vstack([faces, rng.normal(size=(max(poses - 6, 0), 3))])[:poses])
    ups /= np.linalg.norm(ups, axis=1, keepdims=True)
    attitudes = [_attitude(up, h) for up, h in zip(ups, rng.uniform(0.0, 360.0, poses))]
    accel_truth = norm_only_gauge(truth_for_serial("HH-7").parameters_at(25.0))
    force, rate = [], []
    for k, attitude in enumerate(attitudes):
        n = int((6.0 if k == 0 else rng.uniform(3.0, 5.0)) * rate_hz)
        force.append(np.tile(attitude.inv().apply([0.0, 0.0, 1.0]), (n, 1)))
        rate.append(np.zeros((n, 3)))
        if k + 1 == len(attitudes):
            break
        duration = rng.uniform(1.5, 3.0)
        u = np.arange(int(duration * rate_hz)) / (duration * rate_hz)
        profile, speed = 10 * u**3 - 15 * u**4 + 6 * u**5, (30 * u**2 - 60 * u**3 + 30 * u**4) / duration
        turn = (attitude.inv() * attitudes[k + 1]).as_rotvec()  # body frame, constant axis along the move
        path = attitude * Rotation.from_rotvec(profile[:, None] * turn)
        hand = np.sin(2 * np.pi * u)[:, None] * rng.normal(size=3) * 0.2 + rng.normal(0.0, 0.01, (len(u), 3))
        force.append(path.inv().apply(np.array([0.0, 0.0, 1.0]) + hand))
        rate.append(np.degrees(speed[:, None] * turn))
    force_g, rate_dps = np.vstack(force), np.vstack(rate)
    if still_gyro:
        rate_dps = np.zeros_like(rate_dps)
    accel = distort(force_g, accel_truth) + rng.normal(0.0, accel_noise_g, force_g.shape)
    gyro = rate_dps @ TRUE_MATRIX.T + TRUE_BIAS_DPS + rng.normal(0.0, gyro_noise_dps, rate_dps.shape)
    if gsens_dps_per_g is not None:
        gyro = gyro + force_g @ np.asarray(gsens_dps_per_g).T
    return GyroSession(np.arange(len(force_g)) / rate_hz, accel, gyro, accel_truth)


def calibrate(path: Path, **layout: object):
    recording = read_csv_recording(path, CsvLayout.parse_columns(COLUMNS, gyro=GYRO_COLUMNS, **layout))
    detection = detect_static_intervals(recording.t_s, recording.accel_g, recording.temperature_c, DetectorSettings(),
                                        recording.source)
    return recording, detection, fit_recording(recording, detection, "all", "IMU-1")


@pytest.mark.parametrize("units, seed", [("dps", 21), ("rad/s", 22), ("counts", 23)])
def test_bias_and_matrix_recovered_within_three_sigma(tmp_path: Path, units: str, seed: int) -> None:
    session = gyro_session(np.random.default_rng(seed))
    if units == "counts":  # integer codes of a ±2000 °/s part: quantised by 1/16.4 °/s
        data = np.column_stack([session.t_s, session.accel_g, np.full(len(session.t_s), 25.0),
                                np.rint(session.gyro_dps * 16.4)])
        path = tmp_path / "s.csv"
        np.savetxt(path, data, delimiter=",", header=f"{COLUMNS},{GYRO_COLUMNS}", comments="", fmt="%.8f")
        layout: dict[str, object] = {"gyro_units": "counts", "counts_per_dps": 16.4}
    else:
        path = session.write(tmp_path / "s.csv", 1.0 if units == "dps" else np.pi / 180.0)
        layout = {"gyro_units": units}
    recording, detection, result = calibrate(path, **layout)
    gyro = result.gyro
    assert gyro is not None and gyro.segments == len(detection.intervals) - 1 == 15
    z_bias = (gyro.bias_dps - TRUE_BIAS_DPS) / gyro.bias_sigma_dps
    z_matrix = (gyro.matrix - TRUE_MATRIX) / gyro.matrix_sigma
    assert np.all(np.abs(z_bias) < 3.0), z_bias
    assert np.all(np.abs(z_matrix) < 3.0), z_matrix
    # The sigmas mean something: small enough to tell 1 % scale and 0.5 % cross terms from none.
    assert gyro.matrix_sigma.max() < 0.001 and gyro.bias_sigma_dps.max() < 0.01
    assert gyro.rank == 12
    # K = I leaves ~1° of misclosure per move; the fit closes them to the noise of the integrated gyro.
    assert np.sqrt(np.mean(gyro.residual_before_deg**2)) > 0.3
    assert np.sqrt(np.mean(gyro.residual_after_deg**2)) < 0.05
    np.testing.assert_allclose(gyro.correct(TRUE_MATRIX @ [10.0, -20.0, 30.0] + TRUE_BIAS_DPS), [10.0, -20.0, 30.0],
                               atol=0.01)
    # Earth's rate against this bias's 1σ, said either way.
    assert any("Earth's rate" in note and ("above" if EARTH_RATE_DPS > gyro.bias_sigma_dps.max() else "below") in note
               for note in gyro.notes)


def test_the_command_reports_the_gyro_and_keeps_the_calibration_file(tmp_path: Path, capsys) -> None:
    path = gyro_session(np.random.default_rng(24)).write(tmp_path / "s.csv")
    argv = ["fit-recording", str(path), "--columns", COLUMNS, "-o", str(tmp_path / "cal.yaml"),
            "--registry", str(tmp_path / "registry.sqlite")]
    assert main([*argv, "--json"]) == 0
    without = (tmp_path / "cal.yaml").read_text()
    assert json.loads(capsys.readouterr().out)["gyro"] is None
    assert main([*argv, "--gyro-columns", GYRO_COLUMNS, "--json"]) == 0
    gyro = json.loads(capsys.readouterr().out)["gyro"]
    assert {"bias_dps", "bias_sigma_dps", "scale", "scale_sigma", "matrix", "matrix_sigma", "residual_rms_before_deg",
            "residual_rms_after_deg", "segments"} <= set(gyro)
    np.testing.assert_allclose(gyro["scale"], np.diag(gyro["matrix"]))
    assert abs(gyro["scale"][0] - TRUE_MATRIX[0, 0]) < 3 * gyro["scale_sigma"][0]
    assert gyro["residual_rms_after_deg"] < gyro["residual_rms_before_deg"] / 10
    # The calibration file holds the gyroscope as its DUT's gyro channel: bias and K as fitted, the rest of the
    # rate-table model nominal and said to be undetermined; compensating with it is what the fit does.
    assert "gyro" not in without
    calibration = load_calibration(tmp_path / "cal.yaml").channel("s", "gyro")   # the recording names the sensor
    assert calibration.mode == "hand-held" and len(calibration.free_parameters) == 12
    raw = TRUE_MATRIX @ np.array([[10.0, -20.0, 30.0], [-200.0, 5.0, 90.0]]).T + TRUE_BIAS_DPS[:, None]
    expected = (raw.T - np.array(gyro["bias_dps"])) @ np.linalg.inv(np.array(gyro["matrix"])).T
    np.testing.assert_allclose(apply(calibration, raw.T, 25.0, {"acceleration": np.zeros((2, 3))}), expected, rtol=1e-9)
    assert "not taken out" in calibration.statements["earth_rate"] and "not determined" in calibration.statements["gauge"]
    assert main([*argv, "--gyro-columns", GYRO_COLUMNS]) == 0
    out = capsys.readouterr().out
    assert "gyro: 15 moves between static intervals" in out and "Earth's rate" in out


def test_gyro_columns_without_rotations_give_the_bias_alone(tmp_path: Path, capsys) -> None:
    """The gyro reads bias and noise while gravity turns (a splice, or another sensor's gyro): the moves cannot
    say anything of K, so the gyro channel holds what the still intervals determine, its bias, with K nominal
    and the reason in its warnings; the registry records it."""
    path = gyro_session(np.random.default_rng(25), still_gyro=True).write(tmp_path / "still.csv")
    argv = ["fit-recording", str(path), "--columns", COLUMNS, "--gyro-columns", GYRO_COLUMNS,
            "-o", str(tmp_path / "cal.yaml"), "--registry", str(tmp_path / "r.sqlite")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "K not determined" in out and "no rotation between static intervals" in out
    gyro = load_calibration(tmp_path / "cal.yaml").channel("still", "gyro")
    assert gyro.free_parameters == ["bias_x_dps", "bias_y_dps", "bias_z_dps"]
    assert "K is not determined" in gyro.statements["gauge"] and gyro.metrics["k_determined"] is False
    assert any("spliced" in w for w in gyro.warnings)
    bias = np.array([gyro.setpoints[0].parameters[f"bias_{a}_dps"] for a in "xyz"])
    sigma = np.array([gyro.setpoints[0].sigma[f"bias_{a}_dps"] for a in "xyz"])
    assert np.all(np.abs(bias - TRUE_BIAS_DPS) < 3 * sigma), (bias, sigma)
    assert main(["registry", "list", "--registry", str(tmp_path / "r.sqlite"), "--json"]) == 0
    channels = sorted(row["channel"] for row in json.loads(capsys.readouterr().out))
    assert channels == ["accel", "gyro"]


def test_turns_only_about_gravity_leave_the_matrix_undetermined(tmp_path: Path) -> None:
    """Every move changes the heading only: the gravity directions never change, so nothing tells K's
    scale along the vertical, nor anything about the other axes, which never turn: K is not fitted, and the
    note names the terms."""
    path = gyro_session(np.random.default_rng(26), about_gravity_only=True).write(tmp_path / "yaw.csv")
    recording = read_csv_recording(path, CsvLayout.parse_columns(COLUMNS, gyro=GYRO_COLUMNS))
    detection = detect_static_intervals(recording.t_s, recording.accel_g, None, DetectorSettings(), recording.source)
    assert len(detection.intervals) == 16  # the moves are seen (the hand pushes), so the intervals are found
    gravity = np.array([i.mean_g for i in detection.intervals])
    fit = fit_handheld_gyro(recording, detection.intervals, gravity)
    assert not fit.k_determined and np.array_equal(fit.matrix, np.eye(3)) and np.all(np.isnan(fit.matrix_sigma))
    message = fit.notes[0]
    assert "\n" not in message and "the 15 moves between static intervals do not determine the gyro's " in message
    assert "K_zz" in message and "turns about gravity" in message
    # One face up throughout: the forces do not spread, so G cannot be told from the bias.
    assert not fit.gsens_fitted and fit.gsens_p_value is None


#: A g-sensitivity of a few hundredths of °/s per g, as MEMS gyros have (row: gyro axis, column: force axis).
TRUE_GSENS = np.array([[0.030, -0.012, 0.008],
                       [0.015, -0.025, 0.010],
                       [-0.006, 0.020, 0.040]])


@pytest.mark.parametrize("seed", [31, 32])
def test_g_sensitivity_is_fitted_where_the_still_intervals_ask_for_it(tmp_path: Path, seed: int) -> None:
    """The same session with and without G: with it, the F-test asks for G and the fit finds it within 3σ (bias
    and K still within theirs); without it, G is not fitted. The calibration file holds G only when fitted."""
    with_g = gyro_session(np.random.default_rng(seed), gsens_dps_per_g=TRUE_GSENS).write(tmp_path / "g.csv")
    _, _, result = calibrate(with_g)
    gyro = result.gyro
    assert gyro is not None and gyro.k_determined and gyro.gsens_fitted
    assert gyro.gsens_p_value is not None and gyro.gsens_p_value < 1e-3
    z_gsens = (gyro.gsens_dps_per_g - TRUE_GSENS) / gyro.gsens_sigma
    assert np.all(np.abs(z_gsens) < 3.0), z_gsens
    assert np.all(np.abs((gyro.bias_dps - TRUE_BIAS_DPS) / gyro.bias_sigma_dps) < 3.0)
    assert np.all(np.abs((gyro.matrix - TRUE_MATRIX) / gyro.matrix_sigma) < 3.0)
    channel = result.calibration.channel("IMU-1", "gyro")
    assert "gsens_zz_dps_per_g" in channel.free_parameters and "fitted" in channel.statements["g_sensitivity"]
    raw = TRUE_MATRIX @ [10.0, -20.0, 30.0] + TRUE_BIAS_DPS + TRUE_GSENS @ [0.0, 0.0, 1.0]
    np.testing.assert_allclose(apply(channel, raw[None, :], 25.0, {"acceleration": np.array([[0.0, 0.0, 1.0]])})[0],
                               [10.0, -20.0, 30.0], atol=0.02)

    without = gyro_session(np.random.default_rng(seed)).write(tmp_path / "none.csv")
    _, _, result = calibrate(without)
    assert result.gyro is not None and not result.gyro.gsens_fitted
    assert result.gyro.gsens_p_value is not None and result.gyro.gsens_p_value >= 0.01
    assert not any(n.startswith("gsens") for n in result.calibration.channel("IMU-1", "gyro").free_parameters)


@pytest.mark.parametrize("nominal", [80.0, 90.0, 95.0, 100.0, 105.0, 125.0])
def test_any_plausible_counts_per_dps_is_taken_and_k_absorbs_its_error(tmp_path: Path, nominal: float) -> None:
    """Codes of a gyro with 100 codes per °/s, read with a nominal sensitivity up to 20 % off: the fit takes it,
    and K is the true matrix times the ratio (what the nominal got wrong), within 3σ."""
    session = gyro_session(np.random.default_rng(33))
    data = np.column_stack([session.t_s, session.accel_g, np.full(len(session.t_s), 25.0),
                            np.rint(session.gyro_dps * 100.0)])
    path = tmp_path / "codes.csv"
    np.savetxt(path, data, delimiter=",", header=f"{COLUMNS},{GYRO_COLUMNS}", comments="", fmt="%.8f")
    _, _, result = calibrate(path, gyro_units="counts", counts_per_dps=nominal)
    gyro = result.gyro
    assert gyro is not None and gyro.k_determined
    expected = TRUE_MATRIX * 100.0 / nominal
    assert np.all(np.abs((gyro.matrix - expected) / gyro.matrix_sigma) < 3.0)


@pytest.mark.parametrize("argv, expected", [
    (["--gyro-columns", "gx,gy,rate_z"], "no column rate_z (columns: time_s, ax, ay, az, temp_c, gx, gy, gz); map "
                                         "them with --gyro-columns gx,gy,gz"),
    (["--gyro-columns", "gx,gy"], "--gyro-columns: 'gx,gy': expected gx,gy,gz"),
    (["--gyro-columns", "6,7,8"], "--gyro-columns: '6,7,8': by name, as --columns"),
    (["--gyro-columns", GYRO_COLUMNS, "--gyro-units", "counts"], "--counts-per-dps is needed with --gyro-units counts"),
    (["--gyro-columns", GYRO_COLUMNS, "--gyro-units", "rad/s"], "column g"),  # °/s read as rad/s: ×57
    (["--gyro-columns", GYRO_COLUMNS, "--gyro-units", "kdps"], "--gyro-units: invalid choice: 'kdps'"),
])
def test_gyro_column_errors_are_one_line(tmp_path: Path, capsys, argv: list[str], expected: str) -> None:
    session = gyro_session(np.random.default_rng(27), poses=10)
    path = session.write(tmp_path / "s.csv", gyro_scale=60.0)  # turns up to ~100 °/s: 6000 once read as rad/s
    try:
        code = main(["fit-recording", str(path), "--columns", COLUMNS, "-o", str(tmp_path / "cal.yaml"), *argv])
    except SystemExit as exit_:
        code = exit_.code
    assert code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and expected in err, err
    if "rad/s" in argv:
        assert str(path) in err and "check --gyro-units and --counts-per-dps" in err
    assert not (tmp_path / "cal.yaml").exists()


def test_a_gyro_cell_that_is_not_a_number_is_named_by_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "s.csv"
    path.write_text("t,x,y,z,gx,gy,gz\n" + "".join(f"{i / 100},0,0,1,0.1,0.2,0.3\n" for i in range(20))
                    + "0.2,0,0,1,0.1,,0.3\n")
    with pytest.raises(ConfigError, match=r"s\.csv:22: column gy \(--gyro-columns\): not a number \(''"):
        read_csv_recording(path, CsvLayout.parse_columns("t,x,y,z", gyro="gx,gy,gz"))
    mended = tmp_path / "mended.csv"
    mended.write_text(path.read_text().replace(",,", ",0.2,"))
    recording = read_csv_recording(mended, CsvLayout.parse_columns("1,2,3,4", gyro="5,6,7"))  # by number
    assert recording.gyro_dps is not None and recording.gyro_dps.shape == (21, 3) and recording.gyro_lsb_dps == 1.0


# The real imucal session (tests/data/real, as test_real_recording.py reads it): six static poses, then full
# turns about each axis by hand. imucal's Ferraris method knows each turn is 360°; this fit knows only gravity.
DATA = REPO / "tests" / "data" / "real"
SESSION = DATA / "imucal-annotated-session.csv"
COUNTS_PER_DPS = 16.4  # the part's nominal sensitivity (±2000 °/s); imucal's K_g is ~1.0-1.7 % from it
IMUCAL = ["--columns", "samples,acc_x,acc_y,acc_z", "--time-unit", "samples", "--rate-hz", "204.8", "--units",
          "counts", "--counts-per-g", "2048", "--parameters", "bias-scale", "--gyro-columns", "gyr_x,gyr_y,gyr_z",
          "--gyro-units", "counts", "--counts-per-dps", str(COUNTS_PER_DPS)]


def _labelled_rows() -> tuple[list[str], np.ndarray, np.ndarray]:
    import csv

    with open(SESSION, newline="") as handle:
        rows = sorted(csv.DictReader(handle), key=lambda r: int(r["samples"]))
    return ([r["part"] for r in rows], np.array([[float(r[f"acc_{a}"]) for a in "xyz"] for r in rows]),
            np.array([[float(r[f"gyr_{a}"]) for a in "xyz"] for r in rows]))


def test_imucal_session_calibrates_the_gyro_bias_alone_and_says_why(tmp_path: Path, capsys) -> None:
    """The six poses were cut from separate recordings and joined: gravity jumps by 90-180° between them with
    the gyro at rest. The three turns come after the last pose, each a full turn about the axis that points
    up (so about gravity, and ending where it began): invisible to the gravity directions whatever K is.
    imucal's K_g (scale magnitudes) rests on knowing each turn is exactly 360°; nothing here determines it, so
    the gyro channel holds the bias alone, K nominal, the reason said, and the registry records it."""
    parts, accel, _ = _labelled_rows()
    for axis, name in enumerate("xyz"):
        up = accel[[p == f"{name}_rot" for p in parts]].mean(axis=0)
        assert abs(up[axis]) / np.linalg.norm(up) > 0.99, (name, up)  # each turn about the vertical
    output = tmp_path / "cal.yaml"
    argv = ["fit-recording", str(SESSION), *IMUCAL, "-o", str(output), "--registry", str(tmp_path / "r.sqlite")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "K not determined" in out and "in the 5 moves between them" in out and "spliced" in out
    gyro = load_calibration(output).channel(SESSION.stem, "gyro")
    assert gyro.free_parameters == ["bias_x_dps", "bias_y_dps", "bias_z_dps"]
    # Six poses for bias + G (4 terms per axis, 6 degrees of freedom left): the F-test does not ask for G at 1 %.
    assert "not fitted" in gyro.statements["g_sensitivity"]
    # Shorter static intervals bracket the x and z turns too: still no K, and the full turn is named.
    assert main([*argv, "--min-interval-s", "0.3", "-o", str(tmp_path / "short.yaml")]) == 0
    assert "a full turn ends where it began" in capsys.readouterr().out
    assert main(["registry", "list", "--registry", str(tmp_path / "r.sqlite"), "--json"]) == 0
    assert {row["channel"] for row in json.loads(capsys.readouterr().out)} == {"accel", "gyro"}


def test_imucal_session_gyro_bias_agrees_with_imucal() -> None:
    """imucal's b_g is the mean gyro reading over the six labelled poses; ours is the mean over the static
    intervals the detector found inside them (a subset). Two means of nested sample sets differ by
    σ·√(1/n − 1/N) (white noise): 3 of those is the tolerance, about 0.05 count (0.003 °/s)."""
    recording = read_csv_recording(SESSION, CsvLayout.parse_columns(
        "samples,acc_x,acc_y,acc_z", gyro="gyr_x,gyr_y,gyr_z", time_unit="samples", rate_hz=204.8, units="counts",
        counts_per_g=2048.0, gyro_units="counts", counts_per_dps=COUNTS_PER_DPS))
    detection = detect_static_intervals(recording.t_s, recording.accel_g, None, DetectorSettings(), "session")
    bias_dps, _, noise_dps = still_gyro_bias(recording, detection.intervals)
    reference = np.array(json.loads((DATA / "imucal-reference-calibration.json").read_text())["b_g"])
    parts, _, _ = _labelled_rows()
    n, n_labelled = sum(i.n_samples for i in detection.intervals), sum(not p.endswith("_rot") for p in parts)
    assert n < n_labelled
    tolerance = 3.0 * noise_dps * COUNTS_PER_DPS * np.sqrt(1.0 / n - 1.0 / n_labelled)
    assert np.all(tolerance < 0.1)  # the comparison can tell a tenth of a count
    np.testing.assert_array_less(np.abs(np.abs(bias_dps * COUNTS_PER_DPS) - np.abs(reference)), tolerance)
    assert abs(np.linalg.norm(bias_dps * COUNTS_PER_DPS) - np.linalg.norm(reference)) < np.linalg.norm(tolerance)
    # Earth's rate (0.0042 °/s = 0.07 count) is in these means too: above the mean's white-noise 1σ here.
    assert EARTH_RATE_DPS > (noise_dps / np.sqrt(n)).max()
