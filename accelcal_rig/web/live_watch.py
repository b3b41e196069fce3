"""When anything in the registry's live tables changes, for the dashboard's server-sent events: PostgreSQL
says so itself (LISTEN on the channel every publish notifies); an SQLite registry, which cannot, is polled.
One thread per dashboard, started at the first page that listens; a database that goes away is tried again
(polled meanwhile), never a failure of a page."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from accelcal_rig.registry.live import CHANNEL, LiveBoard

#: How often an SQLite registry (or a PostgreSQL one whose LISTEN connection is down) is asked for changes.
POLL_S = 1.0
#: How long a LISTEN waits before it looks whether the dashboard is stopping.
LISTEN_WAIT_S = 5.0


class LiveChanges:
    """A counter that goes up whenever something is published; readers wait for it to move."""

    def __init__(self, board: Callable[[], LiveBoard]) -> None:
        self._board = board
        self._changed = threading.Condition()
        self.version = 0
        self.listening = False      # whether changes come by LISTEN/NOTIFY (else by polling)
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()

    def start(self) -> None:
        with self._changed:
            if self._thread is None:
                self._thread = threading.Thread(target=self._watch, name="live-changes", daemon=True)
                self._thread.start()

    def stop(self) -> None:
        self._stop.set()

    def bump(self) -> None:
        with self._changed:
            self.version += 1
            self._changed.notify_all()

    def _watch(self) -> None:
        seen: Any = None
        while not self._stop.is_set():
            try:
                board = self._board()
                if board.engine.dialect.name == "postgresql" and self._listen(board):
                    self._stop.wait(POLL_S)  # the LISTEN connection failed: a moment, then again
                    continue
                found = board.version()
                if found != seen:
                    seen = found
                    self.bump()
            except Exception:  # noqa: BLE001 - no registry yet, or one gone for a while: the pages say why
                pass
            self._stop.wait(POLL_S)

    def _listen(self, board: LiveBoard) -> bool:
        """LISTEN until the connection fails or the dashboard stops: whether it listened at all."""
        import psycopg
        from psycopg import sql

        url = board.engine.url.set(drivername="postgresql").render_as_string(hide_password=False)
        try:
            connection = psycopg.connect(url, autocommit=True, connect_timeout=10)
        except psycopg.Error:
            return False
        with connection:
            try:
                connection.execute(sql.SQL("LISTEN {}").format(sql.Identifier(CHANNEL)))
                self.listening = True
                self.bump()  # whatever was published before the LISTEN began
                while not self._stop.is_set():
                    if any(True for _ in connection.notifies(timeout=LISTEN_WAIT_S, stop_after=1)):
                        self.bump()
            except psycopg.Error:
                pass
            finally:
                self.listening = False
        return True
