"""Progress while a campaign runs: a live status line on a terminal, timestamped lines everywhere else.

On a terminal (an operator glancing from the door) one line at the bottom shows the state, setpoint,
temperatures, pose count and time left, redrawn at most `REDRAW_S` apart, with log messages printed
above it. Under nohup, systemd or tmux logging to a file, there is no line to redraw: a progress line
is logged whenever the phase changes and every `every_s` of campaign time, with the wall-clock time.
"""

from __future__ import annotations

import logging
import shutil
import sys
import threading
import time
from datetime import datetime, timedelta
from typing import TextIO

from accelcal_rig.core.logger import LOGGER
from accelcal_rig.engine.progress import Progress, ProgressListener

REDRAW_S = 0.2
_CLEAR = "\r\033[K"


def finish_time(progress: Progress, real_clock: bool) -> str:
    """` (done ≈ Tue 03:40)` on the real rig; nothing in a dry run, whose clock is virtual."""
    if not real_clock or progress.remaining_s is None:
        return ""
    done = datetime.now() + timedelta(seconds=progress.remaining_s)
    return f" (done ≈ {done:%a %H:%M})"


class StatusLine:
    """The terminal's bottom line. Log output must go through `TerminalHandler` so it lands above it."""

    def __init__(self, stream: TextIO, real_clock: bool) -> None:
        self.stream = stream
        self.real_clock = real_clock
        self._text = ""
        self._progress: Progress | None = None
        self._drawn_at = 0.0
        self._lock = threading.Lock()

    def __call__(self, progress: Progress) -> None:
        self._progress = progress
        now = time.monotonic()
        if now - self._drawn_at >= REDRAW_S:
            self._drawn_at = now
            with self._lock:
                self._draw()

    def _draw(self) -> None:
        """The line as the terminal is wide now: what gives way is the temperatures, never the time left."""
        width = shutil.get_terminal_size((100, 24)).columns - 1
        done = finish_time(self._progress, self.real_clock) if self._progress is not None else ""
        text = self._progress.line(max(10, width - len(done))) + done if self._progress is not None else ""
        self._text = text[:width]
        self.stream.write(_CLEAR + self._text)
        self.stream.flush()

    def print_above(self, text: str) -> None:
        with self._lock:
            self.stream.write(_CLEAR + text + "\n")
            if self._text:
                self._draw()
            else:
                self.stream.flush()

    def close(self) -> None:
        with self._lock:
            self.stream.write(_CLEAR)
            self.stream.flush()


class TerminalHandler(logging.Handler):
    """Console log handler for a terminal: messages above the status line; progress lines left to it."""

    def __init__(self, status: StatusLine) -> None:
        super().__init__()
        self.status = status

    def filter(self, record: logging.LogRecord) -> bool:
        return not getattr(record, "progress", False) and super().filter(record)

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.status.print_above(self.format(record))
        except Exception:  # noqa: BLE001 - logging's own convention: report, never raise
            self.handleError(record)


class LogFileHandler(logging.FileHandler):
    """The log beside the campaign file. A write that fails (a full disk) stops the log with one warning
    on the console, instead of a traceback per line; the campaign file's event log keeps going."""

    def __init__(self, filename: str, mode: str) -> None:
        super().__init__(filename, mode=mode, encoding="utf-8")
        self.failed = False

    def emit(self, record: logging.LogRecord) -> None:
        if not self.failed:
            super().emit(record)

    def handleError(self, record: logging.LogRecord) -> None:  # noqa: N802 - logging's name
        if self.failed:
            return
        self.failed = True
        error = sys.exc_info()[1]
        print(f"rig: warning: log file {self.baseFilename}: {error}; no more lines go to it (the campaign's own "
              "event log is unaffected)", file=sys.stderr)

    def flush(self) -> None:
        try:
            super().flush()
        except OSError as error:
            if not self.failed:
                self.failed = True
                print(f"rig: warning: log file {self.baseFilename}: {error}", file=sys.stderr)

    def close(self) -> None:
        try:
            super().close()
        except OSError:
            pass  # already reported by flush


class CampaignLog(logging.Handler):
    """The log file beside a campaign, opened only once the campaign has started: until `start`, records are
    kept in memory, so a run that fails before its campaign starts (a dead port) leaves no log behind and a
    refused `--overwrite` does not empty the old campaign's log. `start` writes what was kept, then each
    record as it comes; `discard` drops what was kept."""

    def __init__(self, filename: str, mode: str) -> None:
        super().__init__(logging.DEBUG)
        self.filename, self.mode = filename, mode
        self._kept: list[logging.LogRecord] | None = []
        self._file: LogFileHandler | None = None

    @property
    def started(self) -> bool:
        return self._kept is None

    def start(self) -> None:
        """Open the file and write what was kept. A file that cannot be opened now (its folder was checked
        writable before the run) is one warning, as a failing write is: the campaign's event log goes on."""
        if self._file is not None or self._kept is None:
            return
        try:
            self._file = LogFileHandler(self.filename, self.mode)
        except OSError as exc:
            print(f"rig: warning: log file {self.filename}: {exc.strerror}; no lines go to it (the campaign's own "
                  "event log is unaffected)", file=sys.stderr)
            self._kept = None
            return
        self._file.setFormatter(self.formatter)
        for record in self._kept or ():
            self._file.handle(record)
        self._kept = None

    def discard(self) -> None:
        """Forget what was kept: the campaign never started, and its log is not made."""
        self._kept = []

    def emit(self, record: logging.LogRecord) -> None:
        if self._file is not None:
            self._file.handle(record)
        elif self._kept is not None:
            self._kept.append(record)

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
        super().close()


class ProgressLines:
    """Logs a progress line (marked `progress`) at each new phase and every `every_s` of campaign time."""

    def __init__(self, real_clock: bool, every_s: float = 600.0) -> None:
        self.real_clock = real_clock
        self.every_s = every_s
        self._phase: tuple[float | None, str] | None = None
        self._logged_at_s = float("-inf")

    def __call__(self, progress: Progress) -> None:
        phase = (progress.setpoint_c, progress.phase)
        if phase[0] is None and self._phase is not None and self._phase[0] is None:
            return  # before the first setpoint or after the last: the event log says what happens
        if phase != self._phase or progress.clock_s - self._logged_at_s >= self.every_s:
            self._phase, self._logged_at_s = phase, progress.clock_s
            LOGGER.info("progress: %s%s", progress.line(), finish_time(progress, self.real_clock),
                        extra={"progress": True})


def listeners(*callbacks: ProgressListener) -> ProgressListener:
    """One progress listener calling each of `callbacks` in turn."""

    def notify_all(progress: Progress) -> None:
        for callback in callbacks:
            callback(progress)

    return notify_all
