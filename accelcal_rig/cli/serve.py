"""The work behind `rig serve`: the dashboard's options checked, its app made and its socket listening —
before its address is printed, so whoever reads it can connect at once (and port 0 works) — then served."""

from __future__ import annotations

import argparse
import os
import signal
import socket
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from accelcal_rig.core.extras import install_hint
from accelcal_rig.errors import ConfigError

#: Longest wait, as the dashboard stops, for its open connections (a page's event stream) to close.
SHUTDOWN_S = 2


@dataclass
class Dashboard:
    """A dashboard app and the socket it will be served on."""

    app: Any
    listening: socket.socket
    host: str
    token: str | None
    tls_cert: Path | None
    tls_key: Path | None
    #: The port it listens on, kept: the server closes the socket as it stops.
    port: int = field(init=False)

    def __post_init__(self) -> None:
        self.port = self.listening.getsockname()[1]

    @property
    def address(self) -> str:
        """Where it is served, without the token (fit for a log line)."""
        return f"{'https' if self.tls_cert else 'http'}://{self.host}:{self.port}"

    @property
    def url(self) -> str:
        """Where to open it: its address, the token in the query if it needs one."""
        from urllib.parse import quote

        return f"{self.address}/" + (f"?token={quote(self.token, safe='')}" if self.token else "")

    def serve(self, stops: StopRequests) -> None:
        """Serve it until SIGINT or SIGTERM (`stops`: what asked for a stop before it began, and passes one that
        comes while it starts to the server): uvicorn closes its connections and returns."""
        import uvicorn

        # No lifespan: the app has no start-up or shutdown of its own, and a second Ctrl-C while it stops would
        # cancel uvicorn's wait for one, which it logs as a traceback.
        # An open page holds an event stream (web/lab.py) that never ends by itself: a stop waits for the
        # connections at most SHUTDOWN_S, then closes them.
        config = uvicorn.Config(self.app, log_level="warning", ssl_certfile=self.tls_cert, ssl_keyfile=self.tls_key,
                                lifespan="off", timeout_graceful_shutdown=SHUTDOWN_S)
        server = uvicorn.Server(config)
        stop_streams = getattr(self.app.state, "stop_streams", None)
        handle_exit = server.handle_exit

        def stopping(signum: int, frame: Any) -> None:
            if stop_streams is not None:
                stop_streams()  # the event streams end themselves: no connection is cut
            handle_exit(signum, frame)

        server.handle_exit = stopping  # type: ignore[method-assign,assignment]
        stops.server = server
        if stops.requested:  # asked to stop before it began: nothing to serve
            return
        server.run(sockets=[self.listening])


class StopRequests:
    """SIGINT and SIGTERM from before `rig serve` prints its address until it has stopped: noted, and handed to
    the server once there is one (uvicorn's own handlers take them while it serves, and hand them back here as
    it stops) — never an exception raised wherever the program happens to be: a KeyboardInterrupt inside an
    import, as the server starts, leaves the import lock held ("cannot release un-acquired lock")."""

    def __init__(self) -> None:
        self.requested = False
        self.server: Any = None

    def __call__(self, signum: int, frame: Any) -> None:
        self.requested = True
        if self.server is not None:
            self.server.handle_exit(signum, frame)


@contextmanager
def stop_requests() -> Iterator[StopRequests]:
    """SIGINT and SIGTERM as StopRequests while the dashboard starts and serves; the handlers found are put back
    after. A `rig serve` started with SIGINT ignored (a background job) keeps ignoring it until uvicorn listens
    for it."""
    stops = StopRequests()
    if threading.current_thread() is not threading.main_thread():
        yield stops
        return
    previous = {stop: signal.signal(stop, stops) for stop in (signal.SIGINT, signal.SIGTERM)
                if not (stop == signal.SIGINT and signal.getsignal(stop) is signal.SIG_IGN)}
    try:
        yield stops
    finally:
        for stop, handler in previous.items():
            signal.signal(stop, handler)


@contextmanager
def stops_ignored() -> Iterator[None]:
    """While `rig serve` says it stopped: another Ctrl-C or SIGTERM asks for what is under way already, and
    must not turn the stop into an interrupted command. The handlers are put back after (for a caller that
    goes on, as a test calling `main` does)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {stop: signal.signal(stop, signal.SIG_IGN) for stop in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for stop, handler in previous.items():
            signal.signal(stop, handler)


def stopped_line(dashboard: Dashboard | None) -> str:
    """What `rig serve` says as SIGINT or SIGTERM ends it: what it stopped (never the token)."""
    if dashboard is None:
        return "rig serve: stopped before the dashboard was listening"
    return f"rig serve: stopped (dashboard on {dashboard.address} closed)"


def open_dashboard(args: argparse.Namespace) -> Dashboard:
    """The dashboard `rig serve`'s options describe, listening already; every mistake one line before then."""
    from accelcal_rig.registry.location import configured, registry_url

    try:
        import uvicorn  # noqa: F401 - a missing extra is one line before anything else

        from accelcal_rig.web.app import LOOPBACK_HOSTS, create_app
    except ModuleNotFoundError as exc:
        raise ConfigError(f"rig serve needs {exc.name}: {install_hint('dashboard')}") from None
    token = args.token or os.environ.get("ACCELCAL_DASHBOARD_TOKEN") or None
    _check_access(args.host, token, args.tls_cert, args.tls_key)
    if args.user_header and token is None:
        raise ConfigError(f"--user-header {args.user_header}: needs --token, which the reverse proxy sends "
                          "(Authorization: Bearer TOKEN) and its users never see: only the proxy may name a user")
    folders = args.campaigns or [Path.cwd()]
    missing = [folder for folder in folders if not folder.is_dir()]
    if missing:
        raise ConfigError(f"--campaigns {missing[0]}: not a folder")
    from_config = None
    if args.config is not None:
        from accelcal_rig.config.load import load_rig

        rig = load_rig(args.config)
        from_config = configured(rig.model.registry, rig.path)
    app = create_app(folders, registry_url(args.registry, from_config), token, tls=args.tls_cert is not None,
                     hosts=[*LOOPBACK_HOSTS, args.host], user_header=args.user_header)
    return Dashboard(app, _listen(args.host, args.port), args.host, token, args.tls_cert, args.tls_key)


def _check_access(host: str, token: str | None, tls_cert: Path | None, tls_key: Path | None) -> None:
    """Off the loopback a token; TLS files in pairs, and loadable."""
    import ipaddress

    try:
        loopback = host == "localhost" or ipaddress.ip_address(host).is_loopback
    except ValueError:
        loopback = False
    if not loopback and token is None:
        raise ConfigError(f"--host {host}: off 127.0.0.1 the dashboard needs --token (anyone on the network "
                          "could read it otherwise)")
    if (tls_cert is None) != (tls_key is None):
        raise ConfigError("--tls-cert and --tls-key go together")
    if tls_cert is not None:
        import ssl

        try:  # before anything is printed: a wrong file is one line naming it
            ssl.create_default_context(ssl.Purpose.CLIENT_AUTH).load_cert_chain(tls_cert, tls_key)
        except (OSError, ssl.SSLError) as exc:
            raise ConfigError(f"--tls-cert {tls_cert} --tls-key {tls_key}: cannot load: {exc}") from None


def _listen(host: str, port: int) -> socket.socket:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    listening = socket.socket(family, socket.SOCK_STREAM)
    listening.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        listening.bind((host, int(port)))
    except OSError as exc:
        raise ConfigError(f"--host {host} --port {port}: cannot listen there: {exc.strerror}") from None
    listening.listen(128)
    return listening
