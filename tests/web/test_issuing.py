"""A certificate from draft to issued to amended, as a lab issues it (web/issuing.py, used by `rig approve` and the
dashboard): the draft is marked on every page and unnumbered; the approval issues revision 1 with the approver's
name, function and the electronic approval's record on it; a reissue amends the customer, the date of receipt and
remarks (ISO/IEC 17025 §7.8.8), names the revision it replaces and what changed, and carries everything else over,
the operator included; the next reissue, from the dashboard, carries the amendments over again. Every PDF is read
page by page."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest
from pypdf import PdfReader
from starlette.testclient import TestClient

from accelcal_rig.cli import main
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app
from tests.conftest import REPO

SERIAL = "ADX355-A003"
PASSWORD = "a long enough secret"
ORIGIN = {"origin": "http://127.0.0.1"}


def pages(pdf: Path) -> list[str]:
    return [" ".join(page.extract_text().split()) for page in PdfReader(pdf).pages]


def rig(monkeypatch: pytest.MonkeyPatch, *argv: str, stdin: str = "") -> int:
    monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
    return main([str(a) for a in argv])


def test_draft_issued_amended_and_amended_again(monkeypatch, capsys, tmp_path: Path) -> None:
    registry = normalised(str(tmp_path / "registry.sqlite"))
    campaign = tmp_path / "c.h5"
    assert rig(monkeypatch, "run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q",
               "--no-publish", "--registry", registry, "--operator", "A. Smith", "--customer", "Own Customer AG",
               "--contact", "j.doe@own.example", "--received", "2026-11-20", "--condition", "as new") == 0
    folder = campaign.with_suffix(".certificates")
    draft = pages(folder / f"{SERIAL}.DRAFT.pdf")
    for page in draft:
        assert "DRAFT — NOT ISSUED" in page and "not a certificate until approved" in page
    assert "revision 1" not in " ".join(draft)

    assert rig(monkeypatch, "registry", "user", "add", "jdoe", "--full-name", "Jane Doe", "--role", "approver",
               "--function", "Head of laboratory", "--password-stdin", "--registry", registry,
               stdin=PASSWORD + "\n") == 0
    assert rig(monkeypatch, "approve", campaign, "--as", "jdoe", "--serial", SERIAL, "--customer", "X",
               "--password-stdin", stdin=PASSWORD + "\n") == 2          # the first revision states the campaign's
    assert "only a reissue amends" in capsys.readouterr().err
    assert rig(monkeypatch, "approve", campaign, "--as", "jdoe", "--serial", SERIAL, "--password-stdin",
               stdin=PASSWORD + "\n") == 0
    first = pages(folder / f"{SERIAL}.r1.pdf")
    number = re.search(rf"Certificate ({SERIAL}-[0-9A-F]{{12}}) revision 1", first[0])
    assert number is not None
    for page in first:
        assert f"{number.group(1)} revision 1" in page and "DRAFT" not in page
    text = " ".join(first)
    assert "Jane Doe, Head of laboratory" in text and "approved electronically at" in text
    assert re.search(r"record: the laboratory's registry, calibration \d+, certificate revision 1", text)
    assert str(tmp_path) not in text                               # the lab's paths are its own business
    assert "performed by A. Smith" in text and "customer Own Customer AG" in text
    assert "customer's contact j.doe@own.example" in text

    assert rig(monkeypatch, "approve", campaign, "--as", "jdoe", "--serial", SERIAL, "--reissue", "--reason",
               "the customer's name was wrong", "--received", "2999-01-01", "--password-stdin",
               stdin=PASSWORD + "\n") == 2
    assert "is after the calibration" in capsys.readouterr().err
    assert rig(monkeypatch, "approve", campaign, "--as", "jdoe", "--serial", SERIAL, "--reissue", "--reason",
               "the customer's name was wrong", "--customer", "ACME Sensors GmbH", "--received", "2026-11-21",
               "--remarks", "Recalibration after repair.", "--password-stdin", stdin=PASSWORD + "\n") == 0
    second = pages(folder / f"{SERIAL}.r2.pdf")
    for page in second:
        assert f"{number.group(1)} revision 2" in page and "DRAFT" not in page
    text = " ".join(second)
    assert "Revision 2 replaces revision 1 (issued " in text and "the customer's name was wrong" in text
    assert ("Amended: customer: Own Customer AG → ACME Sensors GmbH; date of receipt: 2026-11-20 → 2026-11-21; "
            "remarks: not stated → Recalibration after repair.") in text
    assert "customer ACME Sensors GmbH" in text and "date of receipt 2026-11-21" in text
    assert "Remarks Recalibration after repair." in text
    for kept in ("performed by A. Smith", "customer's contact j.doe@own.example", "condition on receipt as new"):
        assert kept in text, kept                                 # carried over, not amended

    # The dashboard's reissue carries the amendments over and amends the condition.
    capsys.readouterr()
    assert rig(monkeypatch, "registry", "list", "--serial", SERIAL, "--json", "--registry", registry) == 0
    import json

    row_id = json.loads(capsys.readouterr().out)[0]["id"]
    client = TestClient(create_app([tmp_path], registry), base_url="http://127.0.0.1")
    token = re.search(r'name="csrf" value="([^"]+)"', client.get("/login").text).group(1)
    assert client.post("/login", data={"csrf": token, "name": "jdoe", "password": PASSWORD},
                       headers=ORIGIN).status_code == 200
    page = client.get(f"/registry/calibrations/{row_id}")
    token = re.search(r'name="csrf" value="([^"]+)"', page.text).group(1)
    reissued = client.post(f"/registry/calibrations/{row_id}/decision", headers=ORIGIN, data={
        "csrf": token, "action": "reissue", "password": PASSWORD, "reason": "condition misread",
        "condition": "scratched housing", "customer": ""})
    assert reissued.status_code == 200 and "revision 3 issued" in reissued.text
    third = (folder / f"{SERIAL}.r3.html").read_text()
    assert "ACME Sensors GmbH" in third and "scratched housing" in third and "Recalibration after repair." in third
    assert "Revision 3 replaces revision 2" in third and "condition on receipt: as new → scratched housing" in third
    assert "dashboard, password of registry user jdoe" in third
