"""Request and reply over a serial line: a late reply is never taken for the answer to the next request."""

from __future__ import annotations

import time

import pytest

from accelcal_rig.errors import TransientInstrumentError
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.sim.pty_line_server import PtyLineServer


def test_a_late_reply_is_discarded_not_read_as_the_next_answer() -> None:
    def controller(request: str) -> str:
        if request == "BUSY?":
            time.sleep(0.3)  # answers after the host gave up
            return "1"
        return "0"  # FAULT?: no fault

    server = PtyLineServer(controller).start()
    try:
        line = LinePort.open(server.path, "turntable", 9600, timeout_s=0.2)
        with pytest.raises(TransientInstrumentError, match="'BUSY\\?': no reply within the timeout"):
            line.ask("BUSY?")
        assert line.ask("FAULT?") == "0"  # not the late "1", which would read as a controller fault
        line.close()
    finally:
        server.stop()


def test_of_two_lines_arriving_together_the_last_is_the_answer() -> None:
    server = PtyLineServer(lambda request: "stale\nfresh").start()
    try:
        line = LinePort.open(server.path, "device", 9600, timeout_s=0.5)
        assert line.ask("X") == "fresh"
        line.close()
    finally:
        server.stop()
