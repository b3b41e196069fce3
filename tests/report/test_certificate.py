"""Certificates: one per DUT, HTML and a PDF of at most two pages, stating what the files hold and nothing
they do not; refused for a calibration of other measurements."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from accelcal_rig.errors import ConfigError
from accelcal_rig.report.certificate import write_certificates
from accelcal_rig.store.content import measurements_sha256
from accelcal_rig.store.paths import journal_path
from accelcal_rig.store.read import load_campaign


def test_one_certificate_per_dut_with_what_a_lab_signs(fitted_paper_campaign: tuple[Path, Path], tmp_path: Path) -> None:
    from weasyprint import HTML

    campaign, calibration = fitted_paper_campaign
    written, warnings = write_certificates(campaign, calibration, tmp_path / "certs", operator="A. Smith")
    assert warnings == [] and [w.serial for w in written] == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]
    sha = measurements_sha256(load_campaign(campaign))
    for w in written:
        page = w.html.read_text(encoding="utf-8")
        for expected in (w.serial, "SIMULATED", sha, "PARTID 0xED", "Verification (poses the calibration never saw)",
                         "expanded uncertainty (k = 2, about 95 %)", "turntable pointing", "approved by", "A. Smith",
                         "the standard value", "168 at -40"):
            assert expected in page, expected
        assert page.count("class='verdict PASS'") == 1 and "http" not in page  # nothing fetched from anywhere
        assert w.pdf is not None and w.pdf.read_bytes().startswith(b"%PDF")
        assert 1 <= len(HTML(string=page).render().pages) <= 2


def test_a_calibration_of_other_measurements_is_refused(fitted_paper_campaign: tuple[Path, Path], tmp_path: Path,
                                                        write, workdir: Path) -> None:
    from tests.conftest import TINY_PROCEDURE

    other = workdir / "other.h5"
    assert main(["run", str(write("tiny.yaml", TINY_PROCEDURE)), "--dry-run", "-o", str(other), "-q", "--no-pdf"]) == 0
    _, calibration = fitted_paper_campaign
    with pytest.raises(ConfigError, match="fitted to other measurements than .*other.h5 holds now: fit it again"):
        write_certificates(other, calibration, tmp_path / "certs")
    # The run wrote its own certificates beside it, HTML only as asked.
    assert sorted(p.suffix for p in (workdir / "other.certificates").iterdir()) == [".html"] * 4


def test_a_partial_campaign_says_so_and_fails(paper_campaign: Path, tmp_path: Path, capsys) -> None:
    from tests.conftest import kill_mid_pose

    campaign = tmp_path / "partial.h5"
    shutil.copy(paper_campaign, campaign)
    shutil.copy(journal_path(paper_campaign), journal_path(campaign))
    kill_mid_pose(campaign, 300)  # a run killed at its 301st pose
    calibration = tmp_path / "partial.calibration.yaml"
    registry = tmp_path / "registry.sqlite"
    assert main(["fit", str(campaign), "-o", str(calibration), "--registry", str(registry)]) == 2
    refused = capsys.readouterr().err.strip().splitlines()
    assert len(refused) == 1 and "300 of 432 poses stored, next " in refused[0] and "rig resume" in refused[0]
    assert not calibration.exists() and not registry.exists()                 # nothing written, nothing recorded
    assert main(["fit", str(campaign), "-o", str(calibration), "--registry", str(registry), "--partial"]) == 0
    assert "a partial fit" in capsys.readouterr().err and not registry.exists()   # never a serial's calibration
    assert main(["registry", "add", str(campaign), "--registry", str(registry)]) == 2
    assert "nothing is recorded from half a campaign" in capsys.readouterr().err
    assert main(["certificate", str(campaign), "-o", str(tmp_path / "certs"), "--no-pdf"]) == 0
    page = next((tmp_path / "certs").glob("*.html")).read_text(encoding="utf-8")
    assert "PARTIAL: partial campaign: 300 of 432 poses stored" in page and "class='verdict FAIL'" in page


def test_a_calibration_from_before_budgets_is_refused_in_one_line(fitted_paper_campaign: tuple[Path, Path],
                                                                 tmp_path: Path) -> None:
    import yaml

    campaign, calibration = fitted_paper_campaign
    old = yaml.safe_load(calibration.read_text())
    for dut in old["duts"].values():
        sensor = dut["channels"]["accel"]
        del sensor["metrics"]["uncertainty_budget"], sensor["verdict"]
    (tmp_path / "old.yaml").write_text(yaml.safe_dump(old))
    with pytest.raises(ConfigError, match="has no uncertainty budget or verdict .*: fit it again"):
        write_certificates(campaign, tmp_path / "old.yaml", tmp_path / "certs")
