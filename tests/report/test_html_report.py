"""`rig report`: every figure a valid PNG of sensible size, every file the page refers to present, nothing
fetched from a network; a campaign with too few poses to fit still gets a report that says so."""

from __future__ import annotations

import re
import struct
import sys
from pathlib import Path

import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli import main
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import CampaignAborted
from accelcal_rig.report.html_report import FIGURES, write_report
from tests.conftest import TINY_PROCEDURE

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from the IHDR chunk, after checking the signature."""
    head = path.read_bytes()[:24]
    assert head[:8] == PNG_SIGNATURE and head[12:16] == b"IHDR", f"{path} is not a PNG"
    return struct.unpack(">II", head[16:24])


def referenced_files(page: Path) -> list[str]:
    return re.findall(r'(?:src|href)="([^"]+)"', page.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def paper_report(paper_campaign: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_report(paper_campaign, tmp_path_factory.mktemp("report") / "report")


def test_every_figure_is_a_png_of_sensible_size(paper_report: Path) -> None:
    for name in FIGURES.values():
        path = paper_report.parent / "figures" / name
        width, height = png_size(path)
        assert 600 <= width <= 4000 and 400 <= height <= 4000, (name, width, height)
        assert path.stat().st_size > 20_000, name  # a drawn figure, not an empty canvas


def test_the_page_refers_only_to_files_beside_it(paper_report: Path) -> None:
    references = referenced_files(paper_report)
    assert sorted(references) == sorted(f"figures/{name}" for name in FIGURES.values())
    for reference in references:
        assert not re.match(r"^[a-z]+:|^//", reference)  # no network, no absolute paths
        assert (paper_report.parent / reference).is_file()
    text = paper_report.read_text(encoding="utf-8")
    assert "<script" not in text and "http://" not in text and "https://" not in text


def test_the_page_holds_the_tables_an_engineer_looks_for(paper_report: Path) -> None:
    text = paper_report.read_text(encoding="utf-8")
    for heading in ("Campaign", "Calibration: verification (poses the fit never saw)",
                    "Calibration: in-sample (the poses fitted)", "Uncertainty budget",
                    "Error parameters at the reference temperature", "RMSE of |g| per setpoint",
                    "Error parameters over temperature", "Offset drift before and after compensation", "Soaks",
                    "Against the simulated truth", "Event log"):
        assert f"<h2>{heading}</h2>" in text
    assert text.count("<td class=\"text\">T") >= 14  # one soak row per setpoint, verification setpoints too
    assert "432 of 432 × 4 DUTs × 200 samples" in text
    # Each DUT's verdict beside its verification figures: the 168 verification poses of each.
    assert text.count('<td class="text">PASS</td>') == 4 and text.count("<td>168</td>") == 4
    assert "safe state: sensor ADX355-A004" in text  # the event log, info and above
    assert text.count("<td>±25</td>") == 4  # each ADXL355's data sheet 0 g offset beside its bias
    assert "expanded (k = 2)" in text and "of its verification axis errors against the simulation truth" in text


def test_an_aborted_campaign_with_too_few_poses_gets_a_report_saying_why(write, workdir: Path) -> None:
    prepared = prepare(write("tiny.yaml", TINY_PROCEDURE), faults="turntable_stall_after_min=20")
    campaign = workdir / "aborted.h5"
    with pytest.raises(CampaignAborted):
        run_campaign(prepared, campaign, dry_run=True, seed=0, overwrite=False)
    page = write_report(campaign, workdir / "report")
    text = page.read_text(encoding="utf-8")
    assert "No calibration:" in text and "aborted" in text
    for reference in referenced_files(page):
        png_size(page.parent / reference)


def test_rig_report_cli(paper_campaign: Path, tmp_path: Path, capsys) -> None:
    assert main(["report", str(paper_campaign), "-o", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().out.strip() == f"report → {tmp_path / 'out' / 'index.html'}"


def test_without_matplotlib_the_error_says_how_to_install_it(paper_campaign: Path, tmp_path: Path, capsys,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import fails as if not installed
    assert main(["report", str(paper_campaign), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert re.fullmatch(r"rig: error: rig report needs matplotlib: pip install 'accelcal-rig\[report\]' "
                        r"\(its packages: pip install 'matplotlib>=[0-9.]+'\)", err.strip()), err
    assert not (tmp_path / "out").exists()


def test_a_polynomial_through_as_many_temperatures_as_coefficients_says_so(write, workdir: Path) -> None:
    text = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [20, 40]") + "fit: {polynomial_degree: 1}\n"
    campaign = workdir / "two.h5"
    run_campaign(prepare(write("two.yaml", text)), campaign, dry_run=True, seed=0, overwrite=False)
    page = write_report(campaign, workdir / "report").read_text(encoding="utf-8")
    assert "0 by construction (the polynomial interpolates)" in page  # not a drift of "0.0000 mg"
    assert "No verification poses:" in page
