"""The dashboard's web application (Starlette, pages rendered on the server with Jinja2): campaigns running
and recent, each campaign's progress, temperatures, warnings, report and certificates, and the registry
(search by serial, a sensor's history and trend, a part's lot). Pages refresh themselves by polling the
JSON endpoints with the bundled script. With a token, every request must carry it. Whatever cannot be
served is one styled page with its status (web/errors.py), never a traceback."""

from __future__ import annotations

import hmac
import re
import secrets
import time
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any
from urllib.parse import quote

from jinja2 import Environment, PackageLoader, select_autoescape
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.middleware import Middleware
from starlette.middleware.base import BaseHTTPMiddleware, RequestResponseEndpoint
from starlette.middleware.sessions import SessionMiddleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request
from starlette.responses import FileResponse, HTMLResponse, JSONResponse, PlainTextResponse, RedirectResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from accelcal_rig.errors import RigError
from accelcal_rig.registry.analysis import by_channel, lot_statistics, trend
from accelcal_rig.registry.database import Registry
from accelcal_rig.report.certificate import DRAFT_SUFFIX
from accelcal_rig.web.approval import BEARER_SCOPE_KEY, ApprovalSettings, approval_routes
from accelcal_rig.web.campaigns import CampaignFolders
from accelcal_rig.web.errors import CheckedInput, ErrorPages, Unforeseen, exception_handlers
from accelcal_rig.web.interruptions import resume_markers
from accelcal_rig.web.lab import LabRigs
from accelcal_rig.web.registry_gate import RegistryGate
from accelcal_rig.web.sign_in import SignInPolicy
from accelcal_rig.web.svg import line_plot

_STATIC = Path(__file__).parent / "static"
#: The registry page's filter (`?made=`): every calibration, only real ones, only dry runs.
_MADE: dict[str, bool | None] = {"": None, "real": False, "dry-run": True}
_TOKEN_COOKIE = "accelcal_token"
#: How long the front page waits for the registry's rigs before it shows the campaigns without them, and how
#: long its rigs fragment (each open page's poll) waits before it says the registry is slow.
FRONT_WAIT_S = 0.5
FRAGMENT_WAIT_S = 2.0
#: A page the dashboard serves but did not make (a certificate, a report: files anyone who can write the
#: campaign's folder or the registry could have changed) runs in a sandbox of its own origin: no script of
#: it can read the dashboard's pages, its session or its form token.
SANDBOXED = {"Content-Security-Policy": "sandbox"}
SANDBOXED_SUFFIXES = (".html", ".htm", ".svg", ".xhtml", ".xml")


class _TokenRequired(BaseHTTPMiddleware):
    """Every request carries the token: `?token=` once (then a cookie), the cookie, or `Authorization: Bearer`."""

    def __init__(self, app: Any, token: str, secure: bool) -> None:
        super().__init__(app)
        self._token = token.encode()
        self._secure = secure

    async def dispatch(self, request: Request, call_next: RequestResponseEndpoint) -> Response:
        given = (request.query_params.get("token") or request.cookies.get(_TOKEN_COOKIE)
                 or request.headers.get("authorization", "").removeprefix("Bearer ").strip())
        if not given or not hmac.compare_digest(given.encode(), self._token):  # bytes: any text compares
            return PlainTextResponse("a token is needed: open the address rig serve printed", status_code=401)
        # Sent as a header, the token is the lab's reverse proxy's (its users never see it): only such a
        # request may name its user in the proxy's header (web/approval.py).
        request.scope[BEARER_SCOPE_KEY] = request.headers.get("authorization", "").startswith("Bearer ")
        response = await call_next(request)
        if request.query_params.get("token"):
            response.set_cookie(_TOKEN_COOKIE, self._token.decode(), httponly=True, samesite="strict",
                                secure=self._secure)
        return response


#: Without a token, only these Host names are answered: a page elsewhere cannot reach the dashboard by
#: pointing a name of its own at 127.0.0.1 (DNS rebinding).
LOOPBACK_HOSTS = ["127.0.0.1", "localhost", "::1", "[::1]"]


def create_app(campaign_folders: list[Path], registry_url: str | None, token: str | None = None,
               tls: bool = False, hosts: list[str] | None = None, user_header: str | None = None,
               sign_in: SignInPolicy | None = None, clock: Callable[[], float] = time.monotonic) -> Starlette:
    """`hosts`: the Host names answered without a token (default LOOPBACK_HOSTS); with a token, any.
    `user_header`: the reverse proxy's header naming the authenticated user (web/approval.py); it needs a
    token, which the proxy sends as `Authorization: Bearer`. `sign_in`: how long sessions live and how logins
    are limited (web/sign_in.py; its defaults). `clock`: what a failed registry's probes are timed by."""
    if user_header and not token:
        raise ValueError("a user header needs a token: the proxy sends it, so only the proxy names a user")
    campaigns = CampaignFolders(campaign_folders)
    registry = RegistryGate(registry_url, clock)
    templates = Environment(loader=PackageLoader("accelcal_rig.web", "templates"),
                            autoescape=select_autoescape(["html"]))

    def page(name: str, status: int = 200, **values: Any) -> HTMLResponse:
        return HTMLResponse(templates.get_template(name).render(registry=registry.label, **values), status_code=status)

    async def front(request: Request) -> Response:
        """The campaigns at once; the rigs as far as the registry answers within FRONT_WAIT_S (else the page says
        so, and its polling shows them when it does)."""
        rigs = await rigs_now(FRONT_WAIT_S) if registry.url is not None else {"lab": None, "rigs_error": None}
        summaries = await run_in_threadpool(campaigns.summaries)
        return page("front.html", campaigns=summaries, folders=campaigns.folders, show_rigs=registry.url is not None,
                    **rigs)

    async def rigs_now(wait_s: float) -> dict[str, Any]:
        """The rigs as far as the registry gives them within `wait_s` in all (a slow answer is not a registry
        down: the next poll tries again)."""
        try:
            return await registry.call(lab.overview, turn_wait_s=wait_s, answer_wait_s=wait_s, down_if_late=False)
        except RigError as exc:
            return {"lab": None, "rigs_error": str(exc).splitlines()[0]}

    async def rigs_fragment(request: Request) -> Response:
        rigs = await rigs_now(FRAGMENT_WAIT_S)
        return HTMLResponse(templates.get_template("_rigs.html").render(registry=registry.label, **rigs))

    def rigs_json(request: Request) -> Response:
        found = lab.overview()
        if found["rigs_error"]:
            raise HTTPException(503, found["rigs_error"])
        return JSONResponse(_jsonable(found["lab"]))

    def live_page(request: Request) -> Response:
        found = lab.campaign(request.path_params["key"])
        return page("live.html", **found)

    def live_json(request: Request) -> Response:
        found = lab.campaign(request.path_params["key"])
        return JSONResponse(_jsonable({**found["c"], "events": found["events"], "warning_groups": found["groups"]}))

    def campaigns_json(request: Request) -> Response:
        return JSONResponse(campaigns.summaries())

    def campaign(request: Request) -> Response:
        name = request.path_params["name"]
        try:
            summary, series = campaigns.summary(name), campaigns.series(name)
        except KeyError:
            raise HTTPException(404, f"no campaign {name} in the watched folders") from None
        path = campaigns.path(name)
        plot = line_plot(series.get("t_h", []), {"chamber air": series.get("chamber_c", []),
                                                  "DUTs (mean)": series.get("dut_c", [])},
                         "campaign time (h)", "temperature (°C)", markers=resume_markers(campaigns.interruptions(name)),
                         marker_key="resumed (run N)", gap_key="rig down")
        return page("campaign.html", c=summary, plot=plot, certificates=_certificates(path),
                    report=_report(path))

    def campaign_json(request: Request) -> Response:
        name = request.path_params["name"]
        try:
            return JSONResponse(campaigns.summary(name))
        except KeyError:
            raise HTTPException(404, f"no campaign {name} in the watched folders") from None

    def campaign_file(request: Request) -> Response:
        """A certificate or a report file beside a watched campaign; nothing outside its folders."""
        name = request.path_params["name"]
        try:
            path = campaigns.path(name)
        except KeyError:
            raise HTTPException(404, f"no campaign {name} in the watched folders") from None
        kind, relative = request.path_params["kind"], request.path_params["file"]
        base = {"certificates": path.with_suffix(".certificates"), "report": _report(path)}.get(kind)
        wanted = _inside(base, relative) if base is not None else None
        if wanted is None:
            raise HTTPException(404, "no such file")
        return FileResponse(wanted, headers=SANDBOXED if wanted.suffix.lower() in SANDBOXED_SUFFIXES else None)

    def registry_search(request: Request) -> Response:
        serial = request.query_params.get("serial", "").strip()
        if serial:
            return RedirectResponse(f"/registry/serials/{quote(serial, safe='')}", status_code=303)
        made = request.query_params.get("made", "")
        if made not in _MADE:  # the address checked before the registry is read
            raise HTTPException(400, "made: not one of real, dry-run")
        reg = registry.get()
        rows = reg.calibrations(limit=50, simulated=_MADE[made])
        return page("registry.html", rows=rows, parts=reg.parts(), made_filter=made)

    def serial_page(request: Request) -> Response:
        serial = request.path_params["serial"]
        reg = registry.get()
        every = reg.calibrations(serial=serial) if serial else []
        if not every:
            raise HTTPException(404, f"no calibration of {serial} in the registry" if serial else "no serial given")
        real = [r for r in every if not r["simulated"]]
        rows = real or every  # a serial only dry runs know is shown as such, marked simulated
        decided = {i: {"approve": "approved", "reissue": "approved", "reject": "rejected"}[a]
                   for i, a in reg.last_actions([r["id"] for r in every]).items()}
        channels = [_channel_view(reg, serial, channel, of, not real) for channel, of in by_channel(rows).items()]
        return page("serial.html", serial=serial, rows=every, channels=channels, decisions=decided,
                    only_simulated=not real)

    def part_page(request: Request) -> Response:
        part = request.path_params["part"]
        every = registry.get().calibrations(part=part)
        if not every:
            raise HTTPException(404, f"no calibration of part {part} in the registry")
        real = [r for r in every if not r["simulated"]]
        rows = real or every
        lots = {channel: lot_statistics(of, channel) for channel, of in by_channel(rows).items()}
        return page("part.html", part=part, lots=lots, only_simulated=not real)

    def serial_json(request: Request) -> Response:
        rows = registry.get().calibrations(serial=request.path_params["serial"])
        return JSONResponse({"channels": {channel: _jsonable(trend(of, channel))
                                          for channel, of in by_channel(rows).items()}} if rows else {"channels": {}})

    def gated(handler: Callable[[Request], Response]) -> Callable[[Request], Awaitable[Response]]:
        """A page that reads the registry: run as the registry's turns allow (web/registry_gate.py)."""
        async def endpoint(request: Request) -> Response:
            return await registry.call(handler, request)
        return endpoint

    lab = LabRigs(registry.get, registry.failed, campaigns.ended)
    pages = ErrorPages(templates, registry.label)
    # Outermost the unforeseen error's page; then who may ask (their refusals say nothing of the dashboard,
    # not even which registry: plain text); then the address checked before any route reads it.
    middleware = [Middleware(Unforeseen, pages=pages, on_failure=registry.forget)]
    middleware += ([Middleware(_TokenRequired, token=token, secure=tls)] if token
                   else [Middleware(TrustedHostMiddleware, allowed_hosts=hosts or LOOPBACK_HOSTS)])
    middleware.append(Middleware(CheckedInput, pages=pages))
    # The approver's session: signed with a key made now (a restart logs everyone out), never sent to
    # another site (SameSite=Strict), unreadable by scripts (HttpOnly), HTTPS-only when served over TLS.
    middleware.append(Middleware(SessionMiddleware, secret_key=secrets.token_urlsafe(32), session_cookie="accelcal_session",
                                 same_site="strict", https_only=tls, max_age=8 * 3600))
    app = Starlette(routes=[
        *approval_routes(registry, page, ApprovalSettings(user_header, sign_in)),
        Route("/", front), Route("/api/campaigns", campaigns_json),
        Route("/fragments/rigs", rigs_fragment), Route("/api/rigs", gated(rigs_json)), Route("/api/live/stream", lab.stream),
        Route("/live/{key}", gated(live_page)), Route("/api/live/{key}", gated(live_json)),
        Route("/campaigns/{name}", campaign), Route("/api/campaigns/{name}", campaign_json),
        Route("/campaigns/{name}/{kind}/{file:path}", campaign_file),
        Route("/registry", gated(registry_search)), Route("/registry/serials/{serial:path}", gated(serial_page)),
        Route("/registry/parts/{part}", gated(part_page)),
        Route("/api/registry/serials/{serial:path}", gated(serial_json)),
        Mount("/static", StaticFiles(directory=_STATIC), name="static"),
    ], middleware=middleware, exception_handlers=exception_handlers(pages, registry.failed, registry.forget))
    app.state.stop_streams = lab.stop_streams  # rig serve ends the event streams as it stops
    return app


def _certificates(campaign: Path) -> list[dict[str, str]]:
    """The certificate files beside the campaign, each with what it is: a draft (not issued) or an issued
    revision (report/certificate.py names them so)."""
    folder = campaign.with_suffix(".certificates")
    if not folder.is_dir():
        return []
    found = []
    for name in sorted(p.name for p in folder.glob("*") if p.suffix in (".html", ".pdf")):
        stem = name.rsplit(".", 1)[0]
        revision = re.fullmatch(r".*\.r(\d+)", stem)
        label = ("DRAFT, not issued" if stem.endswith(DRAFT_SUFFIX) else
                 f"issued, revision {revision.group(1)}" if revision else "not a certificate this dashboard wrote")
        found.append({"name": name, "label": label, "draft": "yes" if stem.endswith(DRAFT_SUFFIX) else ""})
    return found


def _inside(base: Path, relative: str) -> Path | None:
    """The file `relative` names under `base`, if it is one there (never one outside, by `..` or a link)."""
    try:
        wanted = (base / relative).resolve()
        return wanted if wanted.is_relative_to(base.resolve()) and wanted.is_file() else None
    except OSError:  # a name the filesystem refuses (too long, not allowed): no such file
        return None


def _report(campaign: Path) -> Path | None:
    """A report `rig report` wrote for it: FILE.report/ beside it."""
    folder = campaign.with_suffix(".report")
    return folder if (folder / "index.html").is_file() else None


def _channel_view(reg: Registry, serial: str, channel: str, rows: list[dict[str, Any]],
                  simulated: bool) -> dict[str, Any]:
    """One channel of a serial as its page shows it: its valid calibration (or why none), its trend and the bias
    plot over time (in the bias's own unit)."""
    result = trend(rows, channel)
    ordered = sorted(rows, key=lambda r: (r["calibrated_at"], r["id"]))
    biased = [r for r in ordered if "bias" in r["figures"]]
    plot = ""
    if biased:
        unit = biased[0]["figures"]["bias"]["unit"]
        times = [(r["calibrated_at"] - biased[0]["calibrated_at"]).total_seconds() / 86400.0 for r in biased]
        plot = line_plot(times, {f"bias {axis}": [r["figures"]["bias"]["value"][k] for r in biased]
                                 for k, axis in enumerate("xyz")},
                         "days since the first calibration", f"bias at the reference temperature ({unit})")
    current = reg.current(serial, simulated=simulated, channel=channel)
    return {"channel": channel, "current": current, "trend": result, "plot": plot, "calibrations": len(rows),
            "why_not_valid": "" if current is not None else reg.why_not_valid(serial, channel)}


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    return value
