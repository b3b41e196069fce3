"""A campaign's follow-up (accelcal_rig/follow_up.py): where a run recorded it goes, `rig status` naming
what of it is missing, and `rig resume` of a complete campaign finishing it once, also after a kill -9 at
a write call after the last pose."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE


def rows_per_serial(registry: Path) -> dict[str, int]:
    with sqlite3.connect(registry) as connection:
        return dict(connection.execute("SELECT serial, count(*) FROM calibrations GROUP BY serial").fetchall())


def status_of(output: Path, capsys) -> dict:
    capsys.readouterr()
    assert main(["status", str(output), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture
def finished(write, tmp_path: Path, capsys) -> tuple[Path, Path, Path]:
    """A tiny dry run with its certificates in a folder of their own and a registry of its own: (campaign,
    certificates, registry)."""
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    output, certificates, registry = procedure.with_suffix(".h5"), tmp_path / "certs", tmp_path / "own.sqlite"
    assert main(["run", str(procedure), "--dry-run", "-o", str(output), "-q", "--no-pdf",
                 "--certificates", str(certificates), "--registry", str(registry)]) == 0
    capsys.readouterr()
    return output, certificates, registry


def test_a_run_records_where_its_follow_up_goes_and_status_finds_it_all_done(finished, capsys) -> None:
    output, certificates, registry = finished
    recorded = json.loads(str(load_campaign(output).attrs["follow_up"]))
    assert recorded["certificates"] == str(certificates.resolve()) and recorded["pdf"] is False
    assert recorded["registry"] == f"sqlite:///{registry.resolve()}"
    parts = {p["part"]: p["state"] for p in status_of(output, capsys)["follow_up"]}
    assert parts == {"calibration": "done", "certificates": "done", "registry": "done"}
    assert set(rows_per_serial(registry).values()) == {1}


def test_status_names_what_is_missing_and_resume_finishes_it_once(finished, capsys) -> None:
    output, certificates, registry = finished
    serials = sorted(rows_per_serial(registry))
    (certificates / f"{serials[1]}.DRAFT.html").unlink()
    with sqlite3.connect(registry) as connection:
        connection.execute("DELETE FROM calibrations WHERE serial = ?", (serials[2],))
    status = status_of(output, capsys)
    parts = {p["part"]: p for p in status["follow_up"]}
    assert parts["certificates"]["state"] == "missing" and serials[1] in parts["certificates"]["detail"]
    assert parts["registry"]["state"] == "missing" and serials[2] in parts["registry"]["detail"]
    assert main(["status", str(output)]) == 0
    text = capsys.readouterr().out
    assert f"next       rig resume {output}  (writes what is missing: certificates, registry)" in text

    assert main(["resume", str(output), "-q"]) == 0  # told nothing: the run's recorded folder and registry
    out = capsys.readouterr().out
    assert "1 calibration recorded" in out and f"{len(serials) - 1} registered already" in out
    assert (certificates / f"{serials[1]}.DRAFT.html").is_file()
    assert rows_per_serial(registry) == {serial: 1 for serial in serials}
    assert {p["state"] for p in status_of(output, capsys)["follow_up"]} == {"done"}
    assert main(["resume", str(output), "-q"]) == 0  # again: nothing to do, nothing recorded twice
    assert "already" in capsys.readouterr().out and rows_per_serial(registry) == {serial: 1 for serial in serials}


def test_a_calibration_fitted_to_other_measurements_is_stale_and_fitted_again(finished, capsys) -> None:
    output, _, registry = finished
    calibration = output.with_suffix(".calibration.yaml")
    calibration.write_text(calibration.read_text().replace("measurements_sha256: ", "measurements_sha256: 00", 1))
    parts = {p["part"]: p for p in status_of(output, capsys)["follow_up"]}
    assert parts["calibration"]["state"] == "stale" and "other measurements" in parts["calibration"]["detail"]
    assert main(["resume", str(output), "-q"]) == 0
    assert {p["state"] for p in status_of(output, capsys)["follow_up"]} == {"done"}
    assert set(rows_per_serial(registry).values()) == {1}


def test_a_certificate_from_another_calibration_is_stale(finished, capsys) -> None:
    output, certificates, _ = finished
    page = sorted(certificates.glob("*.DRAFT.html"))[0]
    page.write_text(page.read_text().replace("DRAFT-", "DRAFT-0"))  # another draft's identifier
    parts = {p["part"]: p for p in status_of(output, capsys)["follow_up"]}
    assert parts["certificates"]["state"] == "stale"


def test_a_reader_of_the_status_creates_no_registry(finished, capsys) -> None:
    output, _, registry = finished
    registry.unlink()
    for side in registry.parent.glob(registry.name + "-*"):
        side.unlink()
    parts = {p["part"]: p for p in status_of(output, capsys)["follow_up"]}
    assert parts["registry"]["state"] == "missing" and "is not made yet" in parts["registry"]["detail"]
    assert not registry.exists()


@pytest.mark.skipif(shutil.which("strace") is None, reason="needs strace (.ci/run installs it)")
@pytest.mark.parametrize(("target", "call", "when"), [("calibration", "fsync", 1), ("certificates", "fsync", 1),
                                                      ("registry", "pwrite64", 1), ("registry", "pwrite64", 12)])
def test_kill_after_the_last_pose_then_one_resume_finishes_everything_once(target: str, call: str, when: int, write,
                                                                           tmp_path: Path, capsys) -> None:
    """kill -9 (strace's injection) just after the calibration is renamed into its own folder (that folder's
    fsync), after the first certificate is (likewise), or at a write of the registry's database: one
    `rig resume` leaves every part there exactly once. (bench/follow_up.py kills at every write call.)"""
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    output, registry = procedure.with_suffix(".h5"), tmp_path / "kill.sqlite"
    folders = {"calibration": tmp_path / "cal", "certificates": tmp_path / "certs"}
    for folder in folders.values():
        folder.mkdir()
    rig = str(Path(sys.executable).parent / "rig")
    argv = [rig, "run", str(procedure), "--dry-run", "-o", str(output), "-q", "--no-pdf", "--registry", str(registry),
            "--calibration", str(folders["calibration"] / "tiny.yaml"), "--certificates", str(folders["certificates"])]
    watched = folders.get(target, registry)  # -P: only the calls on this path (a folder's: its own fsync) count
    killed = subprocess.run(["strace", "-o", "/dev/null", "-P", str(watched), "-e", f"trace={call}", "-e",
                             f"inject={call}:signal=SIGKILL:when={when}", *argv],
                            capture_output=True, text=True, timeout=300, env=os.environ.copy())
    assert killed.returncode != 0, killed.stdout
    stored = load_campaign(output)
    assert len(stored.poses) == stored.poses_planned  # the kill came after the last pose
    assert main(["resume", str(output), "-q"]) == 0  # told nothing: the folders the run recorded
    parts = {p["part"]: p["state"] for p in status_of(output, capsys)["follow_up"]}
    assert parts == {"calibration": "done", "certificates": "done", "registry": "done"}
    assert set(rows_per_serial(registry).values()) == {1} and len(rows_per_serial(registry)) == len(stored.serials)
    assert len(list(folders["certificates"].glob("*.html"))) == len(stored.serials)


def test_a_calibration_of_other_measurements_beside_a_campaign_without_a_fit_is_one_line(finished, write,
                                                                                         capsys) -> None:
    """A procedure that asks for no fit, a calibration of another campaign put beside it: the resume neither
    fits nor certifies, and says why in one line (no traceback)."""
    other_calibration = finished[0].with_suffix(".calibration.yaml")
    procedure = write("nofit.yaml", TINY_PROCEDURE + "fit: {mode: none}\n")
    output = procedure.with_suffix(".h5")
    assert main(["run", str(procedure), "--dry-run", "-o", str(output), "-q", "--no-pdf"]) == 0
    output.with_suffix(".calibration.yaml").write_text(  # the same seed measures the same: another digest
        other_calibration.read_text().replace("measurements_sha256: ", "measurements_sha256: 00", 1))
    capsys.readouterr()
    assert main(["resume", str(output), "-q"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err and "calibration stale" in err, err
