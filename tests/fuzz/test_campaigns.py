"""Damaged campaigns (tests/fuzz/campaigns.py): every reader answers in one line or works, and never
changes what it read; resume and repair mend what they can or refuse in one line. `bench/fuzz.py
campaigns` runs 132 cases through every command as processes, timed and memory-measured; this runs a
sample in-process."""

from __future__ import annotations

import hashlib
import signal
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from tests.conftest import SIM_RIG
from tests.fuzz.campaigns import CALIBRATION, CAMPAIGN, DAMAGES, JOURNAL, damaged_case, make_source

HANG_S = 60
READERS = {
    "status": lambda c, f: ["status", str(c), "--json"],
    "fit": lambda c, f: ["fit", str(c), "-o", str(f / "out.yaml")],
    "tilt": lambda c, f: ["analyze", "tilt", str(c), "--calibration", str(f / CALIBRATION)],
    "fit-recording": lambda c, f: ["fit-recording", str(c), "-o", str(f / "recording.yaml")],
}


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    return make_source(tmp_path_factory.mktemp("source"), SIM_RIG)


def digests(folder: Path) -> dict[str, str]:
    return {name: hashlib.sha256((folder / name).read_bytes()).hexdigest() if (folder / name).is_file() else "-"
            for name in (CAMPAIGN, JOURNAL)}


def answer(argv: list[str], capsys) -> tuple[int, str]:
    def hung(signum, frame):
        raise TimeoutError(f"{argv[0]}: no answer within {HANG_S} s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(HANG_S)
    try:
        code = main(argv)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err, err
    errors = [line for line in err.strip().splitlines() if not line.startswith("rig: warning")]
    assert code in (0, 1, 2) and (code == 0 or len(errors) == 1), (code, err)
    return code, err


@pytest.mark.parametrize("number", range(2 * len(DAMAGES)))
def test_readers_answer_in_one_line_and_never_change_what_they_read(number: int, source: Path, tmp_path: Path,
                                                                     capsys) -> None:
    for name, argv in READERS.items():
        folder = tmp_path / name
        what = damaged_case(number, source, folder)
        before = digests(folder)
        answer(argv(folder / CAMPAIGN, folder), capsys)
        assert digests(folder) == before, (name, what)


@pytest.mark.parametrize("number", range(0, 2 * len(DAMAGES), 3))
def test_resume_mends_what_it_can_and_leaves_a_readable_campaign(number: int, source: Path, tmp_path: Path,
                                                                 capsys) -> None:
    what = damaged_case(number, source, tmp_path)
    code, err = answer(["resume", str(tmp_path / CAMPAIGN), "-q"], capsys)
    if code == 0:  # resumed or complete: then every pose of the plan is stored and the file is current
        status_code, _ = answer(["status", str(tmp_path / CAMPAIGN), "--json"], capsys)
        assert status_code == 0, what
        from accelcal_rig.store.read import campaign_status

        status = campaign_status(tmp_path / CAMPAIGN)
        assert status["state"] == "done" and status["poses_done"] == status["poses_total"], (what, status)
        assert status["campaign_file"] == "current", (what, status)
