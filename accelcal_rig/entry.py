"""The `rig` executable's entry point: Ctrl-C and SIGTERM are handled from the first moment, while the
heavy libraries are still being imported, not only once a campaign runs."""

from __future__ import annotations

import signal
import sys

EXIT_INTERRUPTED = 130


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def run_program() -> None:
    signal.signal(signal.SIGTERM, _interrupt)  # SIGINT already raises KeyboardInterrupt
    try:
        from accelcal_rig.cli import run_program as run
    except KeyboardInterrupt:
        print("rig: interrupted while starting; nothing was done", file=sys.stderr)
        raise SystemExit(EXIT_INTERRUPTED) from None
    run()
