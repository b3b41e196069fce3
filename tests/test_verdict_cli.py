"""A verified campaign end to end through the commands: verification poses stored apart and never fitted,
the verdict in the run summary, `rig status`, `rig fit --json` and the calibration file, and
`--fail-on-reject` exiting 3."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from accelcal_rig.cli import main
from accelcal_rig.fit.acceleration import accelerometer_poses
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.fit.campaign_fit import FitOptions
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE
from tests.fit.vector_poses import fit_accelerometer

VERIFIED = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [20, 40]") + """\
verify: {schedule: {kind: sphere, count: 8}, setpoints_c: [30]}
acceptance: {max_verification_rmse_mg: LIMIT, parameters: {at_c: 30, bias_mg: 100}}
"""


def test_a_dut_beyond_its_limits_fails_and_fail_on_reject_exits_3(write, workdir: Path, capsys) -> None:
    procedure = write("verified.yaml", VERIFIED.replace("LIMIT", "0.001"))  # far below any noise: every DUT fails
    campaign = workdir / "c.h5"
    assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--fail-on-reject"]) == 3
    out, err = capsys.readouterr()
    assert "4 PASS" not in out and "0 PASS, 4 FAIL" in out
    assert out.count("  verdict    ") == 4 and "FAIL: verification |g| RMSE" in out and "limit ≤ 0.001 mg: fail" in out
    assert "4 DUT(s) failed their acceptance limits" in err

    assert main(["status", str(campaign), "--json"]) == 0
    status = json.loads(capsys.readouterr().out)
    assert {v["verdict"] for v in status["verdicts"].values()} == {"FAIL"}
    assert status["calibration"] == str(campaign.with_suffix(".calibration.yaml"))

    calibration = workdir / "again.yaml"
    assert main(["fit", str(campaign), "-o", str(calibration), "--json"]) == 0  # without the flag: 0
    report = json.loads(capsys.readouterr().out)
    for dut in report.values():
        sensor = dut["channels"]["accel"]
        assert dut["verdict"] == "FAIL" and dut["verdict_reasons"][0].startswith("verification |g| RMSE")
        verification = sensor["verification"]
        assert verification["n_poses"] == 3 * 8 and {"rmse_mg", "max_axis_error_mg", "max_tilt_error_deg"} <= set(
            verification)
        assert verification["rmse_mg"] > 0.5 * sensor["noise_floor_mg"]  # held out: no fit can beat its noise here
        assert sensor["in_sample"]["n_poses"] == 2 * 6
        assert sensor["expected_fit_rmse_mg"] < sensor["noise_floor_mg"]
    assert {s.verdict for s in load_calibration(calibration).of_quantity("acceleration").values()} == {"FAIL"}
    assert main(["fit", str(campaign), "-o", str(calibration), "--fail-on-reject"]) == 3


def test_verification_poses_are_stored_apart_and_never_fitted(write, workdir: Path, capsys) -> None:
    procedure = write("verified.yaml", VERIFIED.replace("LIMIT", "1"))
    campaign = workdir / "c.h5"
    assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--fail-on-reject"]) == 0
    assert "4 PASS" in capsys.readouterr().out
    stored = load_campaign(campaign)
    kinds = dict(zip(stored.header.plan.step_key, stored.header.plan.kind))
    assert kinds["T30/verify01"] == "verify" and kinds["T20/pose01"] == "pose" and "T30/pose01" not in kinds
    poses = accelerometer_poses(stored, stored.serials[0])
    assert poses.verification.sum() == 3 * 8 and len(poses.verification) == 2 * 6 + 3 * 8
    with_checks = fit_accelerometer(poses, FitOptions(degree=1))
    without = fit_accelerometer(poses.subset(~poses.verification), FitOptions(degree=1))
    np.testing.assert_array_equal(with_checks.thermal.coefficients, without.thermal.coefficients)
    assert "verification" in with_checks.figures and "verification" not in without.figures


def test_resuming_a_complete_campaign_whose_fit_is_missing_fits_judges_and_certifies(write, workdir: Path,
                                                                                   capsys) -> None:
    procedure = write("verified.yaml", VERIFIED.replace("LIMIT", "0.001"))
    campaign = workdir / "c.h5"
    assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--no-pdf"]) == 0
    capsys.readouterr()
    campaign.with_suffix(".calibration.yaml").unlink()  # as a kill right after the last pose leaves it
    for certificate in campaign.with_suffix(".certificates").iterdir():
        certificate.unlink()
    assert main(["resume", str(campaign), "-q", "--no-pdf", "--fail-on-reject"]) == 3
    out = capsys.readouterr().out
    assert "every pose is stored" in out and out.count("  verdict    ") == 4 and "FAIL: verification |g| RMSE" in out
    assert campaign.with_suffix(".calibration.yaml").exists()
    assert len(list(campaign.with_suffix(".certificates").glob("*.html"))) == 4


def test_resuming_a_complete_rejected_campaign_again_still_fails_on_reject(write, workdir: Path, capsys) -> None:
    procedure = write("verified.yaml", VERIFIED.replace("LIMIT", "0.001"))
    campaign = workdir / "c.h5"
    assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--no-pdf"]) == 0
    capsys.readouterr()
    assert main(["resume", str(campaign), "-q", "--fail-on-reject"]) == 3  # its calibration already judged it
    assert capsys.readouterr().out.count("  verdict    ") == 4


def test_without_limits_nothing_is_judged_and_nothing_is_stated_as_conformity(write, workdir: Path, capsys) -> None:
    """No acceptance limits, no specification: NOT JUDGED in the summary, `rig status`, `rig fit --json`, the
    calibration file and the registry (no verdict, no yield); the certificate states no conformity."""
    procedure = write("unlimited.yaml", VERIFIED.split("acceptance:")[0])
    campaign, registry = workdir / "c.h5", workdir / "registry.sqlite"
    assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--fail-on-reject",
                 "--registry", str(registry)]) == 0
    out = capsys.readouterr().out
    assert "4 NOT JUDGED (no acceptance limits stated)" in out and "PASS" not in out
    assert main(["status", str(campaign), "--json"]) == 0
    verdicts = json.loads(capsys.readouterr().out)["verdicts"]
    assert {v["verdict"] for v in verdicts.values()} == {"NOT JUDGED"}
    assert main(["fit", str(campaign), "-o", str(workdir / "cal.yaml"), "--json", "--registry", str(registry)]) == 0
    assert {r["verdict"] for r in json.loads(capsys.readouterr().out).values()} == {"NOT JUDGED"}
    assert {s.verdict for s in load_calibration(workdir / "cal.yaml").of_quantity("acceleration").values()} == {"NOT JUDGED"}
    page = next((workdir / "c.certificates").glob("*.html")).read_text(encoding="utf-8")
    assert "Statement of conformity" in page and "class='verdict" not in page and "None: the procedure" in page
    assert main(["registry", "list", "--registry", str(registry)]) == 0
    listed = capsys.readouterr().out
    assert listed.count("NOT JUDGED") == 4 and " PASS " not in listed
    assert main(["registry", "stats", "--part", "adxl355", "--registry", str(registry), "--json", "--simulated"]) == 0
    stats = json.loads(capsys.readouterr().out)["channels"]["accel"]
    assert (stats["calibrations"], stats["judged"], stats["passed"], stats["yield"]) == (4, 0, 0, None)


def test_a_limit_inside_the_guard_band_is_conditional_under_guarded_and_pass_under_simple_acceptance(
        write, workdir: Path, capsys) -> None:
    """The same simulated campaign three times (its seed fixed): once to learn each DUT's bias at 30 °C and its
    expanded uncertainty, then with a bias limit half a U beyond the largest, judged by each rule."""
    def run(name: str, acceptance: str) -> dict:
        procedure = write(f"{name}.yaml", VERIFIED.split("acceptance:")[0] + f"acceptance: {acceptance}\n")
        campaign = workdir / f"{name}.h5"
        assert main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--no-pdf"]) == 0
        capsys.readouterr()
        assert main(["fit", str(campaign), "-o", str(workdir / f"{name}.yaml.cal"), "--json"]) == 0
        return json.loads(capsys.readouterr().out)

    learned = run("learn", "{decision_rule: guarded, parameters: {at_c: 30, bias_mg: 1000}}")
    biases = [(serial, c) for serial, dut in learned.items() for c in dut["channels"]["accel"]["decision"]["limits"]]
    assert {c["limit_key"] for _, c in biases} == {"accel.parameters.bias_mg"} and len(biases) == 3 * len(learned)
    assert all(c["outcome"] == "pass" and c["expanded_u"] > 0 for _, c in biases)
    serial, largest = max(biases, key=lambda b: abs(b[1]["value"]))
    limit = abs(largest["value"]) + 0.5 * largest["expanded_u"]

    guarded = run("guarded", f"{{decision_rule: guarded, parameters: {{at_c: 30, bias_mg: {limit!r}}}}}")
    simple = run("simple", f"{{decision_rule: simple, parameters: {{at_c: 30, bias_mg: {limit!r}}}}}")
    same = next(c for c in guarded[serial]["channels"]["accel"]["decision"]["limits"] if c["label"] == largest["label"])
    assert same["value"] == largest["value"]                       # the same measurements, judged again
    assert guarded[serial]["verdict"] == "CONDITIONAL" and same["outcome"] == "conditional pass"
    assert "guarded acceptance" in guarded[serial]["channels"]["accel"]["decision"]["decision_rule"]
    assert simple[serial]["verdict"] == "PASS" and "simple acceptance" in simple[serial]["channels"]["accel"]["decision"]["decision_rule"]
    assert any("conditional pass" in r for r in guarded[serial]["verdict_reasons"])
    assert load_calibration(workdir / "guarded.yaml.cal").channel(serial, "accel").verdict == "CONDITIONAL"
