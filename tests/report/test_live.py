"""The terminal status line and the timestamped progress lines."""

from __future__ import annotations

import io
import logging

import pytest

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.engine.progress import Progress
from accelcal_rig.report import live
from accelcal_rig.report.live import ProgressLines, StatusLine, TerminalHandler


def snapshot(phase: str = "soak", clock_s: float = 0.0, setpoint_c: float | None = -20.0) -> Progress:
    return Progress(state=phase, phase=phase, setpoint_c=setpoint_c, setpoint_number=3, setpoints_total=11,
                    phase_elapsed_s=1390.0, chamber_c=-20.06, dut_c=(-19.61, -19.42), poses_done=48,
                    poses_total=264, clock_s=clock_s, remaining_s=22320.0)


def test_status_line_redraws_below_log_messages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(live, "REDRAW_S", 0.0)
    monkeypatch.setenv("COLUMNS", "200")
    stream = io.StringIO()
    status = StatusLine(stream, real_clock=False)
    handler = TerminalHandler(status)
    handler.setFormatter(logging.Formatter("%(message)s"))
    status(snapshot())
    handler.handle(logging.LogRecord("x", logging.INFO, __file__, 1, "T-20: stable", None, None))
    handler.handle(logging.LogRecord("x", logging.INFO, __file__, 1, "progress: hidden", None, None))
    record = logging.LogRecord("x", logging.INFO, __file__, 1, "progress: shown by the line", None, None)
    record.progress = True
    handler.handle(record)
    status.close()
    text = stream.getvalue()
    line = "T-20 (3/11) soak 0:23:10 · chamber -20.1 °C · DUT -19.61…-19.42 °C · pose 48/264 · 6:12:00 left"
    assert text.startswith("\r\033[K" + line)
    assert "\r\033[KT-20: stable\n\r\033[K" + line in text  # the message above, the line redrawn below it
    assert "shown by the line" not in text
    assert text.endswith("\r\033[K")  # the line is cleared when the run ends


def test_real_clock_line_shows_the_finish_time(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "200")
    stream = io.StringIO()
    StatusLine(stream, real_clock=True)(snapshot())
    assert "6:12:00 left (done ≈ " in stream.getvalue()


def test_progress_lines_at_each_phase_and_every_interval(caplog: pytest.LogCaptureFixture) -> None:
    lines = ProgressLines(real_clock=False, every_s=600.0)
    with caplog.at_level(logging.INFO, logger=LOGGER.name):
        for clock_s in (0.0, 300.0, 600.0, 900.0):
            lines(snapshot("soak", clock_s))
        lines(snapshot("poses", 950.0))
        lines(snapshot("poses", 960.0))
    logged = [r for r in caplog.records if r.getMessage().startswith("progress: ")]
    assert [r.getMessage().split(" · ")[0] for r in logged] == [
        "progress: T-20 (3/11) soak 0:23:10", "progress: T-20 (3/11) soak 0:23:10", "progress: T-20 (3/11) poses 0:23:10"]
    assert all(getattr(r, "progress", False) for r in logged)


@pytest.mark.parametrize("width", [100, 80, 60, 40, 25])
def test_a_narrow_line_keeps_the_time_left(width: int) -> None:
    line = snapshot().line(width)
    assert len(line) <= width and line.endswith("6:12:00 left")
    assert ("pose 48/264" in line) == (width >= 40)
    if width >= 90:
        assert "DUT -19.61…-19.42 °C" in line
