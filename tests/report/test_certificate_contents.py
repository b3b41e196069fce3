"""A certificate states what ISO/IEC 17025:2017 §7.8.2.1 and §7.8.4.1 ask of it, read back from its PDF's text
(pypdf): the laboratory, its address and the place; the customer, the date of receipt and the item's condition;
a unique number with its revision on every page and an end on the last; the procedure with its version and the
paper it follows; the conditions the campaign recorded; the instruments by make, model and serial; the
traceability of each reference, an overdue one and one not stated; and no path, device node or endpoint."""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path

import pytest
import yaml

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.report.certificate_lab import CertificateNumber, certificate_number, draft_identifier
from tests.conftest import SIM_RIG

PROCEDURE = """\
name: lab-tiny
version: "2.1"
rig: lab-rig.yaml
setpoints_c: [5, 30]
soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}
schedule: {kind: six-position}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
frost: {dew_point_margin_c: 3}
"""


def _lab_rig(folder: Path) -> Path:
    """The simulated rig as a lab would state it: its lab, its instruments, its references (the temperature
    reference's calibration long overdue, the site's gravity not stated), a DUT with a customer of its own."""
    rig = yaml.safe_load(SIM_RIG.read_text())
    rig["lab"] = {"name": "Test Metrology Laboratory", "address": "12 Test Road\n12345 Testtown",
                  "place_of_calibration": "room B.104, thermal lab"}
    rig["chamber"].update(make="TestEquity", model="115A", serial="TE-1234", dew_point_c=-20)
    rig["turntable"].update(make="Example Motion", model="3AX-200", serial="T-0042")
    rig["fixture"]["sensors"][0].update(customer="Own Customer AG", received_date="2026-01-15", condition="as new")
    rig["references"] = {
        "turntable_angle": {"make": "Example Motion", "model": "3AX-200", "serial": "T-0042",
                            "certificate": "CAL-ANG-17", "issuer": "Angle Lab", "due_date": "2999-12-31"},
        "temperature": {"make": "Example Thermo", "model": "PRT-100", "serial": "RT-7731",
                        "certificate": "CAL-TEMP-112", "issuer": "Temperature Lab", "due_date": "2001-01-31"}}
    path = folder / "lab-rig.yaml"
    path.write_text(yaml.safe_dump(rig, sort_keys=False, allow_unicode=True))
    return path


@pytest.fixture(scope="module")
def certified(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, list[str]]:
    """(campaign, calibration, warnings on stderr) of a dry run of the lab's rig, certified as PDFs by the run."""
    import contextlib
    import io

    folder = tmp_path_factory.mktemp("lab")
    _lab_rig(folder)
    (folder / "lab-tiny.yaml").write_text(PROCEDURE)
    campaign = folder / "campaign.h5"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["run", str(folder / "lab-tiny.yaml"), "--dry-run", "-o", str(campaign), "-q",
                     "--customer", "ACME Sensors GmbH", "--received", "2026-11-20",
                     "--condition", "sealed in ESD bag, no visible damage", "--operator", "A. Smith"],
                    today=lambda: dt.date(2026, 12, 1))
    assert code == 0, err.getvalue()
    return campaign, campaign.with_suffix(".calibration.yaml"), err.getvalue().splitlines()


def _pages(pdf: Path) -> list[str]:
    from pypdf import PdfReader

    return [" ".join(page.extract_text().split()) for page in PdfReader(pdf).pages]


@pytest.mark.parametrize(("serial", "customer", "received", "condition"), [
    ("ADX355-A001", "Own Customer AG", "2026-01-15", "as new"),
    ("ADX355-A002", "ACME Sensors GmbH", "2026-11-20", "sealed in ESD bag, no visible damage")])
def test_the_pdf_states_every_required_item(certified: tuple[Path, Path, list[str]], serial: str, customer: str,
                                            received: str, condition: str) -> None:
    campaign, calibration, _ = certified
    pdf = campaign.with_suffix(".certificates") / f"{serial}.DRAFT.pdf"
    pages = _pages(pdf)
    text = " ".join(pages)
    number = certificate_number(serial, load_calibration(calibration))
    assert re.fullmatch(rf"{serial}-[0-9A-F]{{12}} revision 1", str(number))
    draft = draft_identifier(serial, load_calibration(calibration))
    assert re.fullmatch(r"DRAFT-[0-9A-F]{10}", draft)
    for page in pages:  # a draft's identifier, never the number its approval will issue, and its mark on every page
        assert draft in page and "DRAFT — NOT ISSUED" in page and "not a certificate until approved" in page
        assert number.base not in page
    assert "End of draft" not in " ".join(pages[:-1]) and f"End of draft {draft}" in pages[-1]
    for expected in (
            "Test Metrology Laboratory", "12 Test Road", "12345 Testtown", "room B.104, thermal lab",   # §7.8.2.1 b, c
            f"customer {customer}", f"date of receipt {received}", f"condition on receipt {condition}",  # e, f, §7.8.2.1 i
            "lab-tiny, version 2.1", "Thermal Calibration of Triaxial Accelerometer for Tilt Measurement",   # method
            "Sensors 23(4), 2105 (2023)",
            "dew point −20.0 °C", "room's temperature and humidity not recorded",
            "chamber TestEquity 115A, serial TE-1234", "turntable Example Motion 3AX-200, serial T-0042",
            "campaign campaign.h5", "calibration campaign.calibration.yaml",
            "turntable angle Example Motion 3AX-200, serial T-0042 CAL-ANG-17 Angle Lab 2999-12-31",  # traceability
            "temperature Example Thermo PRT-100, serial RT-7731 CAL-TEMP-112 Temperature Lab 2001-01-31 OVERDUE",
            "site gravity not stated in the rig config", "Not traceable through the site gravity (its reference not "
            "stated); the temperature (its reference's calibration was overdue", "performed by A. Smith"):
        assert expected in text, expected
    assert "doi:10.3390/s23042105" in text.replace(" ", "")  # a line may break it after the slash
    conditions = re.search(r"chamber air (−?[\d.]+) … ([\d.]+) °C .* DUT (−?[\d.]+) … ([\d.]+) °C", text)
    assert conditions is not None  # the air's and the DUT's ranges over both setpoints, 5 and 30 °C
    air_low, air_high, dut_low, dut_high = (float(v.replace("−", "-")) for v in conditions.groups())
    assert 4 < air_low < 6 < 29 < air_high < 31 and 4 < dut_low < 8 < 28 < dut_high < 31
    for absent in ("/dev/", "pts", "127.0.0.1", "modbus-tcp", str(campaign.parent), "ModbusChamber", "SerialTurntable",
                   "lab-tiny.yaml", "lab-rig.yaml"):
        assert absent not in text, absent


def test_the_run_warned_of_the_overdue_reference(certified: tuple[Path, Path, list[str]]) -> None:
    _, _, err = certified
    overdue = [line for line in err if "references." in line]
    assert len(overdue) == 1 and "references.temperature.due_date: overdue since 2001-01-31" in overdue[0]


def test_a_rig_config_without_a_lab_says_so(write, workdir: Path) -> None:
    from tests.conftest import TINY_PROCEDURE

    rig = workdir / "sim.yaml"
    rig.write_text(re.sub(r"(?ms)^lab:.*?(?=^\S)", "", rig.read_text()))
    assert "lab:" not in rig.read_text()
    assert main(["run", str(write("tiny.yaml", TINY_PROCEDURE)), "--dry-run", "-o", str(workdir / "c.h5"), "-q",
                 "--no-pdf"]) == 0
    page = (workdir / "c.certificates" / "ADX355-A001.DRAFT.html").read_text(encoding="utf-8")
    for expected in ("Laboratory not stated in the rig config", "laboratory not stated in the rig config",
                     "tiny (version not stated in the procedure)", "not stated (the fixture&#x27;s sensor entry, or rig "
                     "run --customer)", "no reference is stated in the rig config"):
        assert expected in page, expected


def test_a_certificate_number_takes_a_revision() -> None:
    first = CertificateNumber("ADX355-A001-0123456789AB")
    assert str(first) == "ADX355-A001-0123456789AB revision 1"
    assert str(first.revised()) == "ADX355-A001-0123456789AB revision 2" and first.revised(5).revision == 5
    with pytest.raises(ValueError, match="revisions count from 1"):
        CertificateNumber("X", 0)
