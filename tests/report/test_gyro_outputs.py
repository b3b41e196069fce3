"""An IMU's certificate and report state both its sensors: the gyroscope's results, verification, uncertainty
and verdict beside the accelerometer's, the noise of each; the NOT CALIBRATED banner only for a gyroscope that
is not calibrated; the DUT FAIL when either sensor fails."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.report.certificate import write_certificates
from accelcal_rig.report.html_report import FIGURES, GYRO_FIGURES, write_report
from tests.report.imu_campaign import copied
from tests.report.test_html_report import png_size, referenced_files


@pytest.fixture(scope="module")
def imu(imu_dry_run: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    return copied(imu_dry_run, tmp_path_factory.mktemp("imu"))


def _edited(calibration: Path, folder: Path, change) -> Path:  # noqa: ANN001 - a function of the YAML data
    data = yaml.safe_load(calibration.read_text())
    for serial, dut in data["duts"].items():
        change(serial, dut)
    edited = folder / "edited.calibration.yaml"
    edited.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    return edited


def test_an_imu_certificate_states_its_gyroscope_as_its_calibration_holds_it(imu: tuple[Path, Path],
                                                                            tmp_path: Path) -> None:
    campaign, calibration_path = imu
    calibration = load_calibration(calibration_path)
    written, _ = write_certificates(campaign, calibration_path, tmp_path / "certs", pdf=False)
    assert [w.serial for w in written] == list(calibration.of_quantity("angular rate")) and len(written) == 4
    for w in written:
        page = w.html.read_text(encoding="utf-8")
        gyro = calibration.channel(w.serial, "gyro")
        v, budget = gyro.metrics["verification"], gyro.metrics["uncertainty_budget"]
        assert "NOT CALIBRATED" not in page and "MEMS IMU: accelerometer and gyroscope" in page
        assert (f"<td class='text'>{v['rmse_dps']:.4f} ± {v['expanded_u']['rmse_dps']:.4f} °/s (before calibration "
                f"{v['rmse_before_dps']:.4f} °/s") in page
        u = v["expanded_u"]
        assert f"{v['max_axis_error_dps']:.4f} ± {u['max_axis_error_dps']:.4f} °/s" in page
        assert f"{v['scale_error_ppm']:.0f} ± {u['scale_error_ppm']:.0f} ppm" in page
        assert f"{v['rate_steps']} at {', '.join(f'{t:g}' for t in v['temperatures_c'])} °C" in page
        for value in (*budget["at_rest"]["expanded_dps"], *budget["at_largest_rate"]["expanded_dps"]):
            assert f"<td>{value:.5f}</td>" in page
        assert "table pointing" in page and "at ±1000 °/s" in page
        assert gyro.statements["earth_rate"] in page.replace("&#x27;", "'") and "the fixture frame as the rate table realises it" in page
        bias_x = gyro.parameters_at(25.0)[0]
        assert f"{bias_x:+.4f} ± " in page  # the bias at the reference temperature with its expanded uncertainty
        arw = gyro.metrics["allan"]["arw_deg_per_rthr"][0]["value"]
        vrw = calibration.channel(w.serial, "accel").metrics["allan"]["vrw_m_s_per_rthr"][0]["value"]
        assert f"{arw:.4f} [" in page and f"{vrw:.5f} [" in page and "angle random walk" in page
        assert page.count("class='verdict PASS'") == 1 and "Gyroscope: <b class='PASS'>PASS</b>" in page


def test_an_imu_certificate_fits_on_three_pages_and_ends_on_its_last(imu: tuple[Path, Path], tmp_path: Path) -> None:
    pytest.importorskip("weasyprint")
    from pypdf import PdfReader

    campaign, calibration = imu
    written, warnings = write_certificates(campaign, calibration, tmp_path / "certs")
    assert warnings == []
    for w in written:
        assert w.pdf is not None and w.pdf.read_bytes().startswith(b"%PDF")
        pages = PdfReader(w.pdf).pages           # two sensors and ISO/IEC 17025's contents: at most three
        assert 1 <= len(pages) <= 3 and "End of draft" in pages[-1].extract_text()
        assert all("End of certificate" not in page.extract_text() for page in pages[:-1])


def test_a_failing_gyroscope_fails_the_imu(imu: tuple[Path, Path], tmp_path: Path) -> None:
    campaign, calibration = imu
    reason = "verification rate RMS error: 0.0105 °/s exceeds 0.001 °/s"

    def fail(serial: str, dut: dict) -> None:
        if serial == "IMU-A002":
            dut["channels"]["gyro"].update(verdict="FAIL", verdict_reasons=[reason])

    written, _ = write_certificates(campaign, _edited(calibration, tmp_path, fail), tmp_path / "certs", pdf=False)
    pages = {w.serial: w.html.read_text(encoding="utf-8") for w in written}
    failed = pages["IMU-A002"]
    assert failed.count("class='verdict FAIL'") == 1 and "class='verdict PASS'" not in failed
    assert "Accelerometer: <b class='PASS'>PASS</b>" in failed and "Gyroscope: <b class='FAIL'>FAIL</b>" in failed
    assert reason in failed
    assert all(page.count("class='verdict PASS'") == 1 for serial, page in pages.items() if serial != "IMU-A002")


def test_a_gyroscope_not_calibrated_keeps_its_banner(imu: tuple[Path, Path], tmp_path: Path) -> None:
    campaign, calibration = imu
    why = "angular rate in dps: measured and stored; not calibrated: too few rate steps"

    def uncalibrated(serial: str, dut: dict) -> None:
        del dut["channels"]["gyro"]
        dut["not_calibrated"] = {"gyro": why}

    written, _ = write_certificates(campaign, _edited(calibration, tmp_path, uncalibrated), tmp_path / "certs", pdf=False)
    page = written[0].html.read_text(encoding="utf-8")
    assert f"NOT CALIBRATED: its gyro channel ({why}). This certificate covers its accel channel only." in page
    assert "Results (gyroscope)" not in page and "MEMS accelerometer channel" in page


def test_the_report_has_the_gyroscope_section_and_figures(imu: tuple[Path, Path], tmp_path: Path) -> None:
    campaign, calibration_path = imu
    page = write_report(campaign, tmp_path / "report")
    text = page.read_text(encoding="utf-8")
    calibration = load_calibration(calibration_path)
    for heading in ("Calibration of every gyroscope (angular rate)", "Gyroscope parameters over temperature",
                    "Noise: Allan deviation"):
        assert f"<h2>{heading}</h2>" in text
    assert "Not calibrated:" not in text and "Fitted from the campaign for this report" in text
    section = text.split("<h2>Calibration of every gyroscope (angular rate)</h2>")[1].split("<h2>")[0]
    for serial, gyro in calibration.of_quantity("angular rate").items():  # the same fit as the file's
        row = re.search(rf"<tr[^>]*><td class=\"text\">{serial}</td><td class=\"text\">gyro</td>"
                        rf"<td class=\"text\">(PASS|FAIL)</td>.*?</tr>", section)
        assert row is not None and row.group(1) == gyro.verdict
        assert f"<td>{gyro.metrics['verification']['rmse_dps']:.4f}</td>" in row.group(0)
        assert f"<td>{gyro.metrics['rmse_after_dps']:.4f}</td>" in row.group(0)
    drawn = [*FIGURES.values(), *GYRO_FIGURES.values(), "angular_rate_parameters.png"]
    assert sorted(referenced_files(page)) == sorted(f"figures/{n}" for n in drawn)
    for name in drawn[len(FIGURES):]:
        width, height = png_size(page.parent / "figures" / name)
        assert width >= 600 and height >= 400 and (page.parent / "figures" / name).stat().st_size > 20_000
    assert text.count(">angle random walk (°/√h)<") == 4 and text.count(">velocity random walk (m/s/√h)<") == 4


def test_without_a_calibration_beside_it_the_report_fits_the_gyroscope_alike(imu: tuple[Path, Path],
                                                                              tmp_path: Path) -> None:
    import shutil

    from accelcal_rig.store.paths import journal_path

    campaign, calibration = imu
    alone = tmp_path / "alone.h5"
    shutil.copy(campaign, alone)
    shutil.copy(journal_path(campaign), journal_path(alone))
    text = write_report(alone, tmp_path / "report").read_text(encoding="utf-8")
    assert "Fitted from the campaign for this report" in text
    assert "<h2>Calibration of every gyroscope (angular rate)</h2>" in text
    expected = load_calibration(calibration).channel("IMU-A001", "gyro").metrics["verification"]["rmse_dps"]
    assert f"<td>{expected:.4f}</td>" in text  # the same fit as rig fit's
