"""What killed or failed commands leave half-built (accelcal_rig/durable.py) is removed by the next command
that owns the file: a campaign's run, resume and repair (which hold its lock: everything beside it), and
the writers of files no lock guards — the calibration, the certificates — only what a process that has
ended left (a live writer's own is never touched)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from accelcal_rig.cli import main
from accelcal_rig.durable import clear_dead_temporaries
from accelcal_rig.store.paths import progress_path
from tests.conftest import TINY_PROCEDURE


def ended_pid() -> int:
    """The pid of a process that has ended (waited for: not reused this soon)."""
    process = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                             check=True)
    return int(process.stdout)


def test_only_a_process_that_has_ended_leaves_its_temporary_behind(tmp_path: Path) -> None:
    target = tmp_path / "c.calibration.yaml"
    dead, alive = tmp_path / f"{target.name}.tmp-{ended_pid()}", tmp_path / f"{target.name}.tmp-{os.getpid()}"
    other = tmp_path / "other.yaml.tmp-1"  # another file's: not this one's to clear
    for path in (dead, alive, other):
        path.write_text("half")
    clear_dead_temporaries(target)
    assert not dead.exists() and alive.exists() and other.exists()


def test_run_fit_and_certificate_clear_what_killed_writers_left(write, capsys) -> None:
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    output = procedure.with_suffix(".h5")
    calibration = output.with_suffix(".calibration.yaml")
    certificates = output.with_suffix(".certificates")
    certificates.mkdir()
    dead = ended_pid()
    left = [calibration.with_name(f"{calibration.name}.tmp-{dead}"),
            certificates / f"ADX355-A001.DRAFT.html.tmp-{dead}", certificates / f"ADX355-A001.DRAFT.pdf.tmp-{dead}",
            progress_path(output).with_name(f"{progress_path(output).name}.tmp-{dead}")]
    for path in left:
        path.write_text("half-built")
    progress_path(output).write_text(json.dumps({"pid": dead, "line": "T30 soak (stale)"}))
    assert main(["run", str(procedure), "--dry-run", "-o", str(output), "-q", "--no-pdf"]) == 0
    assert [p for p in left if p.exists()] == [] and not progress_path(output).exists()

    again = calibration.with_name(f"{calibration.name}.tmp-{ended_pid()}")
    again.write_text("half-built")
    assert main(["fit", str(output), "-o", str(calibration)]) == 0
    assert not again.exists()
    page = certificates / f"ADX355-A002.DRAFT.html.tmp-{ended_pid()}"
    page.write_text("half-built")
    assert main(["certificate", str(output), "-o", str(certificates), "--no-pdf"]) == 0
    assert not page.exists()


def test_repair_and_the_resume_of_a_complete_campaign_clear_a_stale_progress_view(write, capsys) -> None:
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    output = procedure.with_suffix(".h5")
    assert main(["run", str(procedure), "--dry-run", "-o", str(output), "-q", "--no-pdf"]) == 0
    for command in (["repair", str(output)], ["resume", str(output), "-q"]):
        progress_path(output).write_text(json.dumps({"pid": ended_pid(), "line": "T30 soak (stale)"}))
        assert main(command) == 0
        assert not progress_path(output).exists(), command
