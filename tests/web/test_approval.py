"""Approval on the dashboard (Starlette's test client): only an authenticated approver — by registry password,
or named by the lab's reverse proxy — approves or rejects, every such request needs the session's token and
the dashboard's own origin; the certificate revision it issues is served from the registry; the decision is
in the record with how the person was known."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from accelcal_rig.registry.approvals import Approvals
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app

PASSWORD = "approver's secret"
ORIGIN = {"origin": "http://127.0.0.1"}


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str, int]:
    """A finished dry run recorded in a registry with an approver (by password) and a proxy's approver."""
    from accelcal_rig.cli import main
    from tests.conftest import REPO

    folder = tmp_path_factory.mktemp("campaigns")
    registry = normalised(str(folder / "registry.sqlite"))
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(folder / "quick.h5"),
                 "-q", "--no-pdf", "--registry", registry]) == 0
    book = Approvals(Registry.open(registry))
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    book.add_user("proxied", "Pat Roxy", "approver", None)
    row_id = min(r["id"] for r in book.registry.calibrations(serial="ADX355-A001"))
    return folder, registry, row_id


def csrf(page: str) -> str:
    found = re.search(r'name="csrf" value="([^"]+)"', page)
    assert found is not None
    return found.group(1)


def test_an_approver_logs_in_and_approves_and_nothing_else_can(lab) -> None:
    folder, registry, row_id = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry))
    page = client.get(f"/registry/calibrations/{row_id}")
    assert page.status_code == 200 and "awaiting approval" in page.text and "Log in" in page.text
    token = csrf(client.get("/login").text)                # the session's token, as the login form carries it
    decide = f"/registry/calibrations/{row_id}/decision"
    refused = client.post(decide, data={"csrf": token, "action": "approve"}, headers=ORIGIN)
    assert refused.status_code == 403 and "log in as an approver" in refused.text     # no one logged in

    login = client.get("/login")
    wrong = client.post("/login", data={"csrf": csrf(login.text), "name": "jdoe", "password": "guess"}, headers=ORIGIN)
    assert wrong.status_code == 401 and "wrong password" in wrong.text
    assert client.post("/login", data={"csrf": "forged", "name": "jdoe", "password": PASSWORD},
                       headers=ORIGIN).status_code == 403
    entered = client.post("/login", data={"csrf": csrf(client.get("/login").text), "name": "jdoe", "password": PASSWORD,
                                          "next": f"/registry/calibrations/{row_id}"}, headers=ORIGIN,
                          follow_redirects=False)
    assert entered.status_code == 303 and entered.headers["location"] == f"/registry/calibrations/{row_id}"
    cookie = entered.headers["set-cookie"].lower()
    assert "httponly" in cookie and "samesite=strict" in cookie

    page = client.get(f"/registry/calibrations/{row_id}")
    assert "approve as Jane Doe" in page.text and "Read the draft certificate" in page.text
    draft = client.get(f"/registry/calibrations/{row_id}/draft")    # read before deciding
    assert draft.status_code == 200 and draft.headers["content-security-policy"] == "sandbox"
    assert "DRAFT of a calibration certificate" in draft.text and "ADX355-A001" in draft.text
    assert client.get(f"/registry/calibrations/{row_id + 999}/draft").status_code == 404
    token = csrf(page.text)
    # A page on another site, or one that hides where it comes from, cannot decide in her name; nor a form
    # without the session's token.
    for headers in ({"origin": "http://evil.example"}, {"referer": "http://127.0.0.1.evil.example/"}, {}):
        assert client.post(decide, data={"csrf": token, "action": "approve"}, headers=headers).status_code == 403
    assert client.post(decide, data={"action": "approve"}, headers=ORIGIN).status_code == 403
    assert client.post(decide, data={"csrf": token, "action": "delete"}, headers=ORIGIN).status_code == 400
    assert Approvals(Registry.open(registry)).trail(calibration_id=row_id) == []

    unsigned = client.post(decide, data={"csrf": token, "action": "approve", "password": "guess"}, headers=ORIGIN)
    assert unsigned.status_code == 403 and "the password is wrong: nothing was decided" in unsigned.text
    assert Approvals(Registry.open(registry)).trail(calibration_id=row_id) == []
    approved = client.post(decide, data={"csrf": token, "action": "approve", "password": PASSWORD}, headers=ORIGIN)
    assert approved.status_code == 200 and "approved — by Jane Doe" in approved.text
    assert "certificate revision 1" in approved.text and "ADX355-A001.r1.pdf" in approved.text
    beside = folder / "quick.certificates"                # the issued files where the run's certificates are
    assert (beside / "ADX355-A001.r1.html").is_file() and (beside / "ADX355-A001.DRAFT.html").is_file()
    assert "DRAFT" not in (beside / "ADX355-A001.r1.html").read_text()
    pdf = client.get(f"/registry/calibrations/{row_id}/certificates/1.pdf")
    assert pdf.status_code == 200 and pdf.content.startswith(b"%PDF")
    issued = client.get(f"/registry/calibrations/{row_id}/certificates/1.html")
    html = issued.text
    assert "Jane Doe" in html and "DRAFT" not in html and issued.headers["content-security-policy"] == "sandbox"
    assert client.get(f"/registry/calibrations/{row_id}/certificates/2.pdf").status_code == 404
    (decision,) = Approvals(Registry.open(registry)).trail(calibration_id=row_id)
    assert decision["authority"] == "dashboard, password of registry user jdoe" and decision["revision"] == 1


def test_behind_the_labs_proxy_its_header_names_the_approver(lab) -> None:
    """The proxy holds the dashboard's token and sends it as a header; only such a request names its user. A
    client with the token some other way (a cookie, `?token=`) cannot name one."""
    folder, registry, row_id = lab
    other = row_id + 1                                    # another DUT's calibration
    with pytest.raises(ValueError, match="needs a token"):
        create_app([folder], registry, user_header="X-Remote-User")
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry, token="proxy-secret",
                                                                     user_header="X-Remote-User"))
    proxy = {"authorization": "Bearer proxy-secret"}
    assert "reverse proxy" in client.get("/login", headers=proxy).text
    page = client.get(f"/registry/calibrations/{other}", headers={**proxy, "X-Remote-User": "proxied"})
    assert "approve as Pat Roxy" in page.text
    decide = f"/registry/calibrations/{other}/decision"
    form = {"csrf": csrf(page.text), "action": "reject", "reason": "loose mount"}
    assert client.post(decide, data=form, headers={**ORIGIN, **proxy}).status_code == 403     # no user named
    sneaky = client.post(decide, params={"token": "proxy-secret"}, data=form,
                         headers={**ORIGIN, "X-Remote-User": "proxied"})
    assert sneaky.status_code == 403                      # the token, but not as the proxy sends it
    rejected = client.post(decide, data=form, headers={**ORIGIN, **proxy, "X-Remote-User": "proxied"})
    assert rejected.status_code == 200 and "rejected — by Pat Roxy" in rejected.text
    (decision,) = Approvals(Registry.open(registry)).trail(calibration_id=other)
    assert decision["authority"] == "dashboard, reverse proxy header X-Remote-User" and decision["reason"] == "loose mount"


def test_hostile_requests_are_refused_in_a_line(lab) -> None:
    folder, registry, row_id = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry))
    assert client.get("/registry/calibrations/" + "9" * 25).status_code == 404
    assert client.get(f"/registry/calibrations/{row_id}/certificates/{'9' * 25}.pdf").status_code == 404
    token = csrf(client.get("/login").text)
    assert client.post("/login", data={"csrf": token, "name": "jdoe\x00", "password": "x"},
                       headers=ORIGIN).status_code == 400
    assert client.post("/login", content=b"csrf=" + b"x" * 20_000, headers=ORIGIN).status_code == 413
    assert client.post("/login", content=b"\xff\xfe", headers=ORIGIN).status_code == 400
    assert client.get("/login?next=//evil.example").text.count("//evil.example") == 0


def test_an_approval_certifies_only_the_fit_it_approves(lab, tmp_path: Path) -> None:
    """A campaign refitted after its calibration was recorded: approving the recorded calibration would
    certify the new fit's file; refused, nothing recorded."""
    import shutil

    from accelcal_rig.cli import main

    folder, _, _ = lab
    here = tmp_path / "copy"
    here.mkdir()
    for name in ("quick.h5", "quick.calibration.yaml"):
        shutil.copy(folder / name, here / name)
    registry = normalised(str(here / "registry.sqlite"))
    assert main(["registry", "add", str(here / "quick.h5"), "--registry", registry]) == 0
    book = Approvals(Registry.open(registry))
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    row_id = min(r["id"] for r in book.registry.calibrations(serial="ADX355-A001"))
    assert main(["fit", str(here / "quick.h5"), "-o", str(here / "quick.calibration.yaml"), "--degree", "0",
                 "--registry", registry]) == 0                 # a refit beside it, recorded as another calibration
    client = TestClient(base_url="http://127.0.0.1", app=create_app([here], registry))
    login = client.post("/login", data={"csrf": csrf(client.get("/login").text), "name": "jdoe", "password": PASSWORD},
                        headers=ORIGIN)
    assert login.status_code == 200
    page = client.get(f"/registry/calibrations/{row_id}")
    refused = client.post(f"/registry/calibrations/{row_id}/decision", data={"csrf": csrf(page.text),
                                                                             "action": "approve", "password": PASSWORD},
                          headers=ORIGIN)
    assert refused.status_code == 409 and "is not the fit of calibration" in refused.text
    assert book.trail(calibration_id=row_id) == [] and book.certificates(row_id) == []
