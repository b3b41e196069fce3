"""Notifications for unattended runs: a webhook and/or a local command on start, soak, fault, safe, finish and
each finding of the early check (`early_check`: a DUT flagged after a setpoint's poses).

Deliveries run on one background thread, each bounded by `timeout_s`, so a dead webhook or a hanging
command never holds up the campaign; a failure is logged and the campaign goes on. When the run ends
the last notifications (fault, safe, finish) get at most `timeout_s` each to go out before the process
exits.
"""

from __future__ import annotations

import json
import os
import queue
import socket
import subprocess
import threading
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from accelcal_rig.config.rig import NotifyConfig
from accelcal_rig.core.logger import LOGGER

NOTIFICATION_FORMAT = "accelcal-rig notification"


class DeliveryFailed(Exception):
    """The receiver answered, but not with success."""


@dataclass(frozen=True)
class Notification:
    event: str                     # start | soak | fault | safe | finish | early_check
    message: str
    campaign: str                  # the campaign file
    procedure: str
    clock_s: float                 # campaign clock
    poses_done: int
    poses_total: int

    def payload(self) -> dict[str, Any]:
        return {"format": NOTIFICATION_FORMAT, "event": self.event, "message": self.message, "campaign": self.campaign,
                "procedure": self.procedure, "host": socket.gethostname(), "clock_s": self.clock_s,
                "poses_done": self.poses_done, "poses_total": self.poses_total,
                "text": f"[{self.procedure}] {self.event}: {self.message}"}


class Notifier:
    """Queues notifications and delivers them in order on one daemon thread."""

    def __init__(self, config: NotifyConfig) -> None:
        self.config = config
        self._queue: queue.Queue[Notification | None] = queue.Queue()
        self._thread = threading.Thread(target=self._deliver_all, name="notifications", daemon=True)
        self._thread.start()
        self.failures = 0

    def send(self, notification: Notification) -> None:
        """Returns at once; events the config does not ask for are dropped."""
        if notification.event in self.config.events:
            self._queue.put(notification)

    def close(self) -> None:
        """Let queued notifications go out, each within its timeout, then stop the thread."""
        self._queue.put(None)
        pending = self._queue.qsize()
        per_delivery_s = self.config.timeout_s * ((self.config.webhook_url is not None) + bool(self.config.command))
        self._thread.join(timeout=pending * per_delivery_s + 1.0)
        if self._thread.is_alive():
            LOGGER.warning("notifications: %d still undelivered at exit", self._queue.qsize())

    def _deliver_all(self) -> None:
        while (notification := self._queue.get()) is not None:
            payload = notification.payload()
            if self.config.webhook_url:
                self._guarded("webhook", notification, self._post, payload)
            if self.config.command:
                self._guarded("command", notification, self._run_command, payload)

    def _guarded(self, channel: str, notification: Notification, deliver: Callable[[dict[str, Any]], None],
                 payload: dict[str, Any]) -> None:
        try:
            deliver(payload)
            LOGGER.debug("notification %s sent by %s", notification.event, channel)
        except Exception as exc:  # noqa: BLE001 - a notification must never affect the campaign
            self.failures += 1
            LOGGER.warning("notification %s by %s failed: %s", notification.event, channel,
                           _one_line(exc, self.config.timeout_s))

    def _post(self, payload: dict[str, Any]) -> None:
        assert self.config.webhook_url is not None
        request = urllib.request.Request(self.config.webhook_url, data=json.dumps(payload).encode(), method="POST",
                                         headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(request, timeout=self.config.timeout_s) as response:
            if not 200 <= response.status < 300:
                raise DeliveryFailed(f"HTTP {response.status}")

    def _run_command(self, payload: dict[str, Any]) -> None:
        """The command gets the notification as JSON on stdin and as RIG_EVENT / RIG_MESSAGE variables."""
        environment = {**os.environ, "RIG_EVENT": payload["event"], "RIG_MESSAGE": payload["message"],
                       "RIG_CAMPAIGN": payload["campaign"], "RIG_TEXT": payload["text"]}
        completed = subprocess.run(self.config.command, input=json.dumps(payload), text=True, capture_output=True,
                                   env=environment, timeout=self.config.timeout_s, check=False)
        if completed.returncode != 0:
            detail = (completed.stderr or completed.stdout).strip().splitlines()
            raise DeliveryFailed(f"exit code {completed.returncode}" + (f": {detail[-1]}" if detail else ""))


def _one_line(exc: Exception, timeout_s: float) -> str:
    if isinstance(exc, DeliveryFailed):
        return str(exc)
    if isinstance(exc, urllib.error.HTTPError):
        return f"HTTP {exc.code} {exc.reason}"
    if isinstance(exc, urllib.error.URLError):
        return f"timed out after {timeout_s:g} s" if isinstance(exc.reason, TimeoutError) else f"{exc.reason}"
    if isinstance(exc, (TimeoutError, subprocess.TimeoutExpired)):
        return f"timed out after {timeout_s:g} s"
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
