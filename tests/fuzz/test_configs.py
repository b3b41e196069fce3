"""Mutated procedure and rig files (tests/fuzz/configs.py): each is valid or refused in one line naming
the file, exit 2, in bounded time. `bench/fuzz.py configs` runs 600 of them as processes, with their time
and memory measured; this runs a sample in-process."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from tests.fuzz.configs import config_case

#: A case that takes this long is a hang (the benchmark holds them to 10 s as processes).
HANG_S = 30


@pytest.fixture
def hang_guard():
    def hung(signum, frame):
        raise TimeoutError(f"no answer within {HANG_S} s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(HANG_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.mark.parametrize("number", range(0, 1200, 10))
def test_a_mutated_config_is_valid_or_one_line(number: int, tmp_path: Path, capsys, hang_guard) -> None:
    case = config_case(number)
    procedure = case.write(tmp_path)
    code = main(["plan", str(procedure)])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err, (case.mutation, err)
    if code == 0:
        assert err == "", (case.mutation, err)
    else:
        assert code == 2 and len(err.strip().splitlines()) == 1, (case.mutation, err)
        named = tmp_path / ("procedure.yaml" if case.mutated == "procedure" else "rig.yaml")
        assert str(named) in err or "procedure.yaml" in err, (case.mutation, err)
