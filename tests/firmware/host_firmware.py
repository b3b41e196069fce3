"""The host build of the bridge firmware (firmware/), for the tests of tests/firmware: building it with its own
Makefile and running it on a pseudo-terminal. The build itself is the session fixture `bridge_host`
(conftest.py). Why the tests run it on the board clock: test_bridge_firmware.py's docstring."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from tests.conftest import REPO

FIRMWARE = REPO / "firmware"
#: The seed every test gives the C models' noise (their samples are recomputed from it).
SEED = 1
#: How long a wait on the firmware may take before the test fails: generous, as a loaded machine is slow.
DEADLINE_S = 10.0


def make(target: str, build: Path) -> str:
    """Run the firmware's Makefile; a failing build fails the test with the compiler's own words."""
    run = subprocess.run(["make", "-C", str(FIRMWARE), target, f"BUILD={build}"], capture_output=True, text=True)
    assert run.returncode == 0, f"make {target} failed:\n{run.stdout}\n{run.stderr}"
    return run.stdout


@dataclass
class Firmware:
    path: str
    process: subprocess.Popen[str]


def wait_until(done: Callable[[], bool], what: str, deadline_s: float = DEADLINE_S) -> None:
    """Poll `done` until it holds; fail naming `what` if it does not within the deadline."""
    give_up = time.monotonic() + deadline_s
    while not done():
        assert time.monotonic() < give_up, f"{what}: not within {deadline_s} s"
        time.sleep(0.002)


@contextmanager
def running(binary: Path, *options: str, clock: str = "board") -> Iterator[Firmware]:
    """The host firmware serving its pseudo-terminal, on `clock` (see test_bridge_firmware.py's docstring); it
    exits when its stdin closes, so a test that dies leaves nothing behind."""
    process = subprocess.Popen([str(binary), "--exit-with-stdin", "--seed", str(SEED), "--clock", clock, *options],
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        path = process.stdout.readline().strip()
        assert path.startswith("/dev/"), f"the firmware printed no pseudo-terminal path ({path!r})"
        yield Firmware(path, process)
    finally:
        assert process.stdin is not None
        process.stdin.close()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
