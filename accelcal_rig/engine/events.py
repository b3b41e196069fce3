"""The campaign's event log: every transition, soak, pose and fault goes to the file and to the log."""

from __future__ import annotations

import logging

from accelcal_rig.core.clock import Clock
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.store.records import Event
from accelcal_rig.store.writer import CampaignWriter

_LEVELS = {"debug": logging.DEBUG, "info": logging.INFO, "warning": logging.WARNING, "error": logging.ERROR}


class EventLog:
    """Stamps events with clock time; `debug` events reach the console only when asked for."""

    def __init__(self, clock: Clock, writer: CampaignWriter | None = None) -> None:
        self._clock = clock
        self._writer = writer

    def emit(self, level: str, kind: str, message: str) -> None:
        t_s = self._clock.now()
        if self._writer is not None:
            try:
                self._writer.log_event(Event(t_s, level, kind, message))
            except Exception as exc:  # noqa: BLE001 - logging must never stop a campaign or its safe state
                LOGGER.error("event not written to the campaign file (%s): %s", exc, message)
        # Marked as the campaign's event, for whoever follows the log for them (registry/publisher.py).
        LOGGER.log(_LEVELS[level], "[%s] %s", format_duration(t_s), message,
                   extra={"event_kind": kind, "clock_s": t_s, "event_message": message})

    def info(self, kind: str, message: str) -> None:
        self.emit("info", kind, message)

    def debug(self, kind: str, message: str) -> None:
        self.emit("debug", kind, message)

    def warning(self, kind: str, message: str) -> None:
        self.emit("warning", kind, message)

    def error(self, kind: str, message: str) -> None:
        self.emit("error", kind, message)
