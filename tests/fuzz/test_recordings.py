"""Mutated recordings and options for `rig fit-recording` (tests/fuzz/recordings.py), drawn by
hypothesis: a calibration file, or one line and exit 2. `bench/fuzz.py recordings` runs 300 of them as
processes, timed and memory-measured."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from accelcal_rig.cli import main
from tests.fuzz.recordings import clean_recording, recording_case


@pytest.fixture(scope="module")
def clean() -> str:
    return clean_recording()


@settings(max_examples=80, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(number=st.integers(min_value=0, max_value=10**6))
def test_a_mutated_recording_is_fitted_or_refused_in_one_line(number: int, clean: str, capsys) -> None:
    case = recording_case(number, clean)
    with tempfile.TemporaryDirectory() as folder:
        try:
            code = main(case.argv(Path(folder)))
        except SystemExit as exit_:  # a command-line mistake: argparse exits
            code = exit_.code
        written = (Path(folder) / "out.yaml").is_file()
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err, (case.mutation, err)
    if code == 0:
        assert written, case.mutation
    else:
        errors = [line for line in err.strip().splitlines() if not line.startswith("warning")]
        assert code == 2 and len(errors) == 1, (case.mutation, err)
        assert not written, case.mutation
