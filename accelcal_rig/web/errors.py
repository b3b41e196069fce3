"""How the dashboard answers what it cannot serve: one styled page (or, under /api/, `{"error": "..."}`) with
the status and one line saying what was wrong — never a traceback, an exception's name or the token.

400 bad input (refused before any route sees it: a NUL or control character, an address that is not UTF-8,
an over-long segment or query), 403/409/413 a refused form, 404 nothing there, 405 a method an address does
not take, 429 too many failed logins (with Retry-After), 503 the registry cannot be read, is down or busy
(the registry layer's one line, which names it without a password), 500 anything unforeseen (one line on the
server's log; the page says only that it happened)."""

from __future__ import annotations

import logging
import re
import traceback
import unicodedata
from collections.abc import Callable, Mapping
from http import HTTPStatus
from typing import Any
from urllib.parse import unquote_to_bytes

from jinja2 import Environment
from sqlalchemy.exc import SQLAlchemyError
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from accelcal_rig.errors import RigError

LOGGER = logging.getLogger("accelcal_rig.web")
#: A file name's limit on every common filesystem; no campaign, certificate, serial or part is longer.
MAX_SEGMENT_BYTES = 255
MAX_PATH_BYTES = 2048
MAX_QUERY_BYTES = 4096
#: The longest line an error page shows (a message quoting a long value is cut there).
MAX_MESSAGE = 300
_TITLES = {400: "Bad request", 403: "Refused", 404: "Not found", 405: "Not allowed here", 409: "Refused",
           413: "Too large", 429: "Too many attempts", 500: "Internal error", 503: "Registry unavailable"}
#: Messages for Starlette's own errors (its detail is only the status's phrase).
_DEFAULTS = {404: "there is no page at this address", 405: "this address does not take that method"}
#: A driver's exception named in a message, "(sqlite3.DatabaseError) " as SQLAlchemy writes it: not for a page.
_EXCEPTION_NAME = re.compile(r"\((?:\w+\.)*\w*(?:Error|Exception|Warning)\)\s*")
UNFORESEEN = "an internal error happened: it is logged in rig serve's output; please report it"


class ErrorPages:
    """Renders every error alike: the dashboard's styled page, or a small JSON body under /api/."""

    def __init__(self, templates: Environment, registry_label: str) -> None:
        self._templates = templates
        self.registry_label = registry_label

    def response(self, path: str, status: int, message: str, headers: Mapping[str, str] | None = None) -> Response:
        message = _one_line(message)
        if path.startswith("/api/"):
            return JSONResponse({"error": message}, status_code=status, headers=headers)
        title = _TITLES.get(status) or HTTPStatus(status).phrase
        back = ("/registry", "the registry") if path.startswith(("/registry", "/login", "/logout")) else ("/", "the campaigns")
        # An unforeseen error may come before the token was checked: its page names not even the registry.
        html = self._templates.get_template("error.html").render(
            registry=self.registry_label if status != 500 else "", status=status, title=title, message=message,
            back=back[0], back_label=back[1])
        return HTMLResponse(html, status_code=status, headers=headers)


def exception_handlers(pages: ErrorPages, on_failure: Callable[[BaseException], None],
                       on_unforeseen: Callable[[], None]) -> dict[Any, Callable[..., Any]]:
    """Starlette's handlers: HTTPException (the routes' own and Starlette's 404/405) by its status, a
    registry that cannot be read 503, and (ServerErrorMiddleware's, a last resort behind `Unforeseen`) 500.
    `on_failure`: the registry failed (web/registry_gate.py: taken as down until a probe finds it back);
    `on_unforeseen`: something else did (the registry opened afresh at the next request, in case it was it)."""

    async def http_error(request: Request, exc: Exception) -> Response:
        assert isinstance(exc, HTTPException)
        detail = exc.detail if exc.detail != HTTPStatus(exc.status_code).phrase else ""
        message = detail or _DEFAULTS.get(exc.status_code) or HTTPStatus(exc.status_code).phrase.lower()
        return pages.response(request.url.path, exc.status_code, message, exc.headers)

    async def registry_error(request: Request, exc: Exception) -> Response:
        on_failure(exc)
        return pages.response(request.url.path, 503, registry_reason(exc, pages.registry_label))

    async def unforeseen(request: Request, exc: Exception) -> Response:
        on_unforeseen()
        log_unforeseen(request.method, request.url.path, exc)
        return pages.response(request.url.path, 500, UNFORESEEN)

    return {HTTPException: http_error, RigError: registry_error, SQLAlchemyError: registry_error, Exception: unforeseen}


def registry_reason(exc: Exception, label: str) -> str:
    """The one line a user reads: the registry layer's own (RigError, naming the registry), else the
    database's message (never the SQL, nor the exception's name)."""
    if isinstance(exc, SQLAlchemyError):
        cause = getattr(exc, "orig", None)
        reason = f"registry {label}: cannot be read: {cause if cause is not None else 'a database error'}"
    else:
        reason = str(exc)
    return _EXCEPTION_NAME.sub("", reason)


def log_unforeseen(method: str, path: str, exc: BaseException) -> None:
    """One line on the server's log: what, where in the code, for which request (its path, not its query,
    which may hold the token)."""
    frames = traceback.extract_tb(exc.__traceback__)
    where = f" at {frames[-1].filename}:{frames[-1].lineno}" if frames else ""
    first = "".join(c if c.isprintable() else "?" for c in (str(exc).splitlines() or [""])[0][:200])
    LOGGER.error("rig serve: %s %r: internal error %s: %s%s", method, path[:200], type(exc).__name__, first, where)


def _one_line(message: str) -> str:
    """The first line, cut to a length a page shows."""
    line = (message.splitlines() or [""])[0].strip() or "an error"
    return line if len(line) <= MAX_MESSAGE else line[:MAX_MESSAGE] + "…"


class CheckedInput:
    """Refuses (400) an address no route could use before any route reads it: a NUL or another control or
    formatting character (a right-to-left override disguises what a page shows), bytes that are not UTF-8,
    a segment longer than a file name may be, an address or query over-long."""

    def __init__(self, app: ASGIApp, pages: ErrorPages) -> None:
        self.app = app
        self.pages = pages

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        problem = input_problem(scope) if scope["type"] == "http" else None
        if problem is None:
            await self.app(scope, receive, send)
            return
        await self.pages.response(scope["path"], 400, problem)(scope, receive, send)


def input_problem(scope: Scope) -> str | None:
    """What is wrong with a request's address, or None."""
    raw_path = scope.get("raw_path") or scope["path"].encode("utf-8")
    query = scope.get("query_string", b"")
    if len(raw_path) > MAX_PATH_BYTES * 3 or len(query) > MAX_QUERY_BYTES * 3:
        return "an address too long"
    try:
        path = unquote_to_bytes(raw_path).decode("utf-8")
        values = unquote_to_bytes(query.replace(b"+", b" ")).decode("utf-8")
    except UnicodeDecodeError:
        return "an address that is not UTF-8 text"
    if len(path.encode()) > MAX_PATH_BYTES or len(values.encode()) > MAX_QUERY_BYTES:
        return "an address too long"
    if any(len(segment.encode()) > MAX_SEGMENT_BYTES for segment in path.split("/")):
        return f"a part of the address longer than {MAX_SEGMENT_BYTES} bytes"
    if _has_control(path) or _has_control(values):
        return "a NUL, control or formatting character in the address"
    return None


def _has_control(text: str) -> bool:
    """A control (Cc: NUL, newline) or formatting (Cf: a bidirectional override) character."""
    return any(unicodedata.category(c) in ("Cc", "Cf") for c in text if not c.isprintable())


class Unforeseen:
    """Outermost: an exception nothing else handled becomes the styled 500 page and one line on the log, so
    the server never prints a traceback for a request. (Starlette's ServerErrorMiddleware would answer the
    same page but raise it on to the server, which logs the whole traceback.)"""

    def __init__(self, app: ASGIApp, pages: ErrorPages, on_failure: Callable[[], None]) -> None:
        self.app = app
        self.pages = pages
        self.on_failure = on_failure

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = False

        async def sending(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, receive, sending)
        except Exception as exc:  # noqa: BLE001 - the one place every unforeseen error is answered
            self.on_failure()
            log_unforeseen(scope.get("method", ""), scope["path"], exc)
            if started:  # half a response sent: the server must drop the connection
                raise
            await self.pages.response(scope["path"], 500, UNFORESEEN)(scope, receive, send)
