"""`rig approve` end to end: a registry user with the approver role, known by their password, approves a
DUT's calibration; its certificate is issued as revision 1 naming them, beside the campaign and in the
registry; a reissue is revision 2 with its reason, revision 1 still retrievable; every decision is in the
audit; a wrong password, a viewer, a missing reason are each one line and exit 2."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from pypdf import PdfReader

from accelcal_rig.cli import main
from accelcal_rig.registry.location import normalised
from tests.conftest import REPO

SERIAL = "ADX355-A002"
PASSWORD = "a long enough secret"


@pytest.fixture(scope="module")
def fitted(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    folder = tmp_path_factory.mktemp("approve")
    registry = normalised(str(folder / "registry.sqlite"))
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(folder / "c.h5"), "-q",
                 "--no-pdf", "--registry", registry]) == 0
    return folder / "c.h5", registry


def rig(monkeypatch: pytest.MonkeyPatch, *argv: str, stdin: str = "") -> int:
    monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
    return main(list(argv))


def test_an_approver_issues_revisions_and_every_decision_is_audited(fitted, monkeypatch, capsys, tmp_path) -> None:
    campaign, registry = fitted
    folder = campaign.with_suffix(".certificates")
    assert "DRAFT: not issued" in (folder / f"{SERIAL}.DRAFT.html").read_text()     # the run's certificate is a draft
    assert rig(monkeypatch, "registry", "user", "add", "jdoe", "--full-name", "Jane Doe", "--role", "approver",
               "--password-stdin", "--registry", registry, stdin=PASSWORD + "\n") == 0
    assert rig(monkeypatch, "registry", "user", "add", "vic", "--full-name", "Vic Viewer", "--password-stdin",
               "--registry", registry, stdin=PASSWORD + "\n") == 2            # the lab has an approver now
    assert "--by APPROVER (with their password) is needed" in capsys.readouterr().err
    assert rig(monkeypatch, "registry", "user", "add", "vic", "--full-name", "Vic Viewer", "--by", "jdoe",
               "--password-stdin", "--registry", registry, stdin="not her password\n" + PASSWORD + "\n") == 2
    assert "user jdoe: wrong password" in capsys.readouterr().err
    assert rig(monkeypatch, "registry", "user", "add", "vic", "--full-name", "Vic Viewer", "--by", "jdoe",
               "--password-stdin", "--registry", registry, stdin=PASSWORD + "\n" + PASSWORD + "\n") == 0
    capsys.readouterr()

    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--password-stdin",
               "--registry", registry, stdin="wrong password\n") == 2
    assert "user jdoe: wrong password" in capsys.readouterr().err
    assert rig(monkeypatch, "approve", str(campaign), "--as", "vic", "--password-stdin", "--registry", registry,
               stdin=PASSWORD + "\n") == 2
    assert "user vic may not approve (role viewer)" in capsys.readouterr().err

    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--password-stdin",
               "--registry", registry, "--operator", "A. Smith", stdin=PASSWORD + "\n") == 0
    out = capsys.readouterr().out
    assert f"{SERIAL}: approved by Jane Doe; certificate" in out and "revision 1 →" in out
    pages = [" ".join(page.extract_text().split()) for page in PdfReader(folder / f"{SERIAL}.r1.pdf").pages]
    text = " ".join(pages)
    assert "Jane Doe" in text and "A. Smith" in text
    for page in pages:                                   # the issued number on every page, no draft mark on any
        assert "revision 1" in page and "DRAFT" not in page
    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--password-stdin",
               "--registry", registry, stdin=PASSWORD + "\n") == 0
    assert "approved already (revision 1, by Jane Doe)" in capsys.readouterr().out
    issued_pdf = (folder / f"{SERIAL}.r1.pdf").read_bytes()
    (folder / f"{SERIAL}.r1.pdf").unlink()           # as a kill after the registry recorded it leaves it
    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--password-stdin",
               "--registry", registry, stdin=PASSWORD + "\n") == 0
    assert "its certificate written again" in capsys.readouterr().out
    assert (folder / f"{SERIAL}.r1.pdf").read_bytes() == issued_pdf      # as issued, from the registry

    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--reissue",
               "--password-stdin", "--no-pdf", "--registry", registry, stdin=PASSWORD + "\n") == 2
    assert "a reissue needs a reason" in capsys.readouterr().err
    assert rig(monkeypatch, "approve", str(campaign), "--as", "jdoe", "--serial", SERIAL, "--reissue", "--reason",
               "customer's address corrected", "--password-stdin", "--no-pdf", "--registry", registry,
               stdin=PASSWORD + "\n") == 0
    assert "revision 2 →" in capsys.readouterr().out
    second = (folder / f"{SERIAL}.r2.html").read_text()
    assert "Revision 2 replaces revision 1 (issued " in second and "customer&#x27;s address corrected" in second
    assert "Nothing amended: the same statements, reissued." in second
    assert (folder / f"{SERIAL}.r1.pdf").is_file()                    # the earlier revision stays

    assert rig(monkeypatch, "registry", "list", "--serial", SERIAL, "--json", "--registry", registry) == 0
    import json

    (row,) = json.loads(capsys.readouterr().out)
    copy = tmp_path / "r1.pdf"
    assert rig(monkeypatch, "registry", "certificate", str(row["id"]), "--revision", "1", "-o", str(copy),
               "--registry", registry) == 0
    assert copy.read_bytes() == (folder / f"{SERIAL}.r1.pdf").read_bytes()   # as issued, from the registry
    assert rig(monkeypatch, "registry", "certificate", str(row["id"]), "--registry", registry) == 0
    listed = capsys.readouterr().out
    assert "revision 1" in listed and "revision 2" in listed and "customer's address corrected" in listed

    assert rig(monkeypatch, "registry", "audit", SERIAL, "--registry", registry) == 0
    audit = capsys.readouterr().out.splitlines()
    assert [line.split()[5] for line in audit] == ["approve", "reissue"]
    assert all("by Jane Doe (rig approve, password of registry user jdoe" in line for line in audit)


def test_a_dry_runs_printed_next_step_works_as_printed(monkeypatch, capsys, tmp_path) -> None:
    """The README's dry run, then what it prints: add an approver where its rows are (the dry runs' registry,
    named however the run found it) and approve. Nothing sends the user to a command that then says there is
    nothing to do; the issued certificate is marked SIMULATED."""
    import re
    import shlex

    monkeypatch.setenv("ACCELCAL_DRY_RUN_REGISTRY", str(tmp_path / "rehearsals.sqlite"))
    monkeypatch.setenv("ACCELCAL_REGISTRY", str(tmp_path / "lab.sqlite"))
    campaign = tmp_path / "c.h5"
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(campaign), "-q",
                 "--no-pdf", "--no-publish"]) == 0
    said = capsys.readouterr().out
    found = re.search(r"certificates are drafts until approved: (rig approve .+ --as USER), USER an approver in "
                      r"registry (\S+) \(once: (rig registry user add .+)\)$", said, re.MULTILINE)
    assert found is not None, said
    add = shlex.split(found.group(3).replace("USER", "jdoe").replace("NAME", "'Jane Doe'"))
    assert rig(monkeypatch, *add[1:], "--password-stdin", stdin=PASSWORD + "\n") == 0
    approve = shlex.split(found.group(1).replace("USER", "jdoe"))
    assert rig(monkeypatch, *approve[1:], "--serial", SERIAL, "--password-stdin", stdin=PASSWORD + "\n") == 0
    out = capsys.readouterr().out
    assert f"{SERIAL}: approved by Jane Doe" in out and "(SIMULATED: a dry run's, in the dry runs' registry)" in out
    issued = (tmp_path / "c.certificates" / f"{SERIAL}.r1.html").read_text()
    assert "SIMULATED" in issued and "DRAFT" not in issued
    assert not (tmp_path / "lab.sqlite").exists()                 # the lab's registry never saw the rehearsal
