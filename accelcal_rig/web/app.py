"""The dashboard's web application (Starlette, pages rendered on the server with Jinja2): campaigns running
and recent, each campaign's progress, temperatures, warnings, report and certificates, and the registry
(search by serial, a sensor's history and trend, a part's lot). Pages refresh themselves by polling the
JSON endpoints with the bundled script. With a token, every request must carry it."""

from __future__ import annotations

import hmac
import secrets
from pathlib import Path
from typing import Any
from urllib.parse import quote

from jinja2 import Environment, PackageLoader, select_autoescape
from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.middleware.base import BaseHTTPMiddleware, RequestResponseEndpoint
from starlette.middleware.sessions import SessionMiddleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request
from starlette.responses import FileResponse, HTMLResponse, JSONResponse, PlainTextResponse, RedirectResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from accelcal_rig.registry.analysis import lot_statistics, trend
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import described
from accelcal_rig.web.approval import BEARER_SCOPE_KEY, ApprovalSettings, approval_routes
from accelcal_rig.web.campaigns import CampaignFolders
from accelcal_rig.web.svg import line_plot

_STATIC = Path(__file__).parent / "static"
#: The registry page's filter (`?made=`): every calibration, only real ones, only dry runs.
_MADE: dict[str, bool | None] = {"": None, "real": False, "dry-run": True}
_TOKEN_COOKIE = "accelcal_token"


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
               tls: bool = False, hosts: list[str] | None = None, user_header: str | None = None) -> Starlette:
    """`hosts`: the Host names answered without a token (default LOOPBACK_HOSTS); with a token, any.
    `user_header`: the reverse proxy's header naming the authenticated user (web/approval.py); it needs a
    token, which the proxy sends as `Authorization: Bearer`."""
    if user_header and not token:
        raise ValueError("a user header needs a token: the proxy sends it, so only the proxy names a user")
    campaigns = CampaignFolders(campaign_folders)
    registry = _LazyRegistry(registry_url)
    templates = Environment(loader=PackageLoader("accelcal_rig.web", "templates"),
                            autoescape=select_autoescape(["html"]))

    def page(name: str, status: int = 200, **values: Any) -> HTMLResponse:
        return HTMLResponse(templates.get_template(name).render(registry=registry.label, **values), status_code=status)

    def front(request: Request) -> Response:
        return page("front.html", campaigns=campaigns.summaries(), folders=campaigns.folders)

    def campaigns_json(request: Request) -> Response:
        return JSONResponse(campaigns.summaries())

    def campaign(request: Request) -> Response:
        name = request.path_params["name"]
        try:
            summary, series = campaigns.summary(name), campaigns.series(name)
        except KeyError:
            return PlainTextResponse(f"no campaign {name} in the watched folders", status_code=404)
        path = campaigns.path(name)
        plot = line_plot(series.get("t_h", []), {"chamber air": series.get("chamber_c", []),
                                                  "DUTs (mean)": series.get("dut_c", [])},
                         "campaign time (h)", "temperature (°C)")
        return page("campaign.html", c=summary, plot=plot, certificates=_certificates(path),
                    report=_report(path))

    def campaign_json(request: Request) -> Response:
        try:
            return JSONResponse(campaigns.summary(request.path_params["name"]))
        except KeyError:
            return JSONResponse({"error": "no such campaign"}, status_code=404)

    def campaign_file(request: Request) -> Response:
        """A certificate or a report file beside a watched campaign; nothing outside its folders."""
        try:
            path = campaigns.path(request.path_params["name"])
        except KeyError:
            return PlainTextResponse("no such campaign", status_code=404)
        kind, relative = request.path_params["kind"], request.path_params["file"]
        base = {"certificates": path.with_suffix(".certificates"), "report": _report(path)}.get(kind)
        if base is None:
            return PlainTextResponse("no such file", status_code=404)
        wanted = (base / relative).resolve()
        if not wanted.is_relative_to(base.resolve()) or not wanted.is_file():
            return PlainTextResponse("no such file", status_code=404)
        return FileResponse(wanted)

    def registry_search(request: Request) -> Response:
        serial = request.query_params.get("serial", "").strip()
        if serial:
            return RedirectResponse(f"/registry/serials/{quote(serial, safe='')}", status_code=303)
        reg = registry.get()
        made = request.query_params.get("made", "")
        if made not in _MADE:
            return PlainTextResponse(f"made={made}: not one of real, dry-run", status_code=400)
        rows = reg.calibrations(limit=50, simulated=_MADE[made])
        return page("registry.html", rows=rows, parts=reg.parts(), made_filter=made)

    def serial_page(request: Request) -> Response:
        serial = request.path_params["serial"]
        reg = registry.get()
        every = reg.calibrations(serial=serial)
        if not every:
            return page("registry.html", rows=[], parts=[], missing=serial, made_filter="")
        real = [r for r in every if not r["simulated"]]
        rows = real or every  # a serial only dry runs know is shown as such, marked simulated
        result = trend(rows)
        points = result["calibrations"]
        accel = [r for r in rows if r["channel"] == "accel"]  # the plot and trend are the accelerometer's
        times = [(r["calibrated_at"] - accel[-1]["calibrated_at"]).total_seconds() / 86400.0 for r in reversed(accel)]
        plot = line_plot(times, {f"bias {axis}": [p["bias_mg"][k] for p in points] for k, axis in enumerate("xyz")},
                         "days since the first calibration", "bias at the reference temperature (mg)")
        gyro = trend(rows, "gyro") if any(r["channel"] == "gyro" for r in rows) else None
        decided = {i: {"approve": "approved", "reissue": "approved", "reject": "rejected"}[a]
                   for i, a in reg.last_actions([r["id"] for r in every]).items()}
        return page("serial.html", serial=serial, rows=every, current=reg.current(serial, simulated=not real),
                    why_not_valid=reg.why_not_valid(serial), decisions=decided,
                    gyro_why_not_valid=reg.why_not_valid(serial, "gyro") if gyro else "",
                    trend=result, plot=plot, only_simulated=not real, gyro_trend=gyro,
                    gyro_current=reg.current(serial, simulated=not real, channel="gyro") if gyro else None)

    def part_page(request: Request) -> Response:
        part = request.path_params["part"]
        every = registry.get().calibrations(part=part)
        real = [r for r in every if not r["simulated"]]
        rows = real or every
        gyro = [r for r in rows if r["channel"] == "gyro"]
        return page("part.html", part=part, stats=lot_statistics(rows) if rows else None, only_simulated=not real,
                    gyro_stats=lot_statistics(gyro, "gyro") if gyro else None)

    def serial_json(request: Request) -> Response:
        rows = registry.get().calibrations(serial=request.path_params["serial"])
        return JSONResponse(_jsonable(trend(rows)) if rows else {"calibrations": []})

    middleware = ([Middleware(_TokenRequired, token=token, secure=tls)] if token
                  else [Middleware(TrustedHostMiddleware, allowed_hosts=hosts or LOOPBACK_HOSTS)])
    # The approver's session: signed with a key made now (a restart logs everyone out), never sent to
    # another site (SameSite=Strict), unreadable by scripts (HttpOnly), HTTPS-only when served over TLS.
    middleware.append(Middleware(SessionMiddleware, secret_key=secrets.token_urlsafe(32), session_cookie="accelcal_session",
                                 same_site="strict", https_only=tls, max_age=8 * 3600))
    return Starlette(routes=[
        *approval_routes(registry, page, ApprovalSettings(user_header)),
        Route("/", front), Route("/api/campaigns", campaigns_json),
        Route("/campaigns/{name}", campaign), Route("/api/campaigns/{name}", campaign_json),
        Route("/campaigns/{name}/{kind}/{file:path}", campaign_file),
        Route("/registry", registry_search), Route("/registry/serials/{serial:path}", serial_page),
        Route("/registry/parts/{part}", part_page), Route("/api/registry/serials/{serial:path}", serial_json),
        Mount("/static", StaticFiles(directory=_STATIC), name="static"),
    ], middleware=middleware)


class _LazyRegistry:
    """The registry, opened at its first use (a dashboard of campaigns works without one)."""

    def __init__(self, url: str | None) -> None:
        self.url = url
        self._registry: Registry | None = None
        self.label = described(url) if url else "none"

    def get(self) -> Registry:
        if self._registry is None:
            if self.url is None:
                raise RuntimeError("no registry")
            self._registry = Registry.open(self.url, upgrade=False)  # a view changes no schema
        return self._registry


def _certificates(campaign: Path) -> list[str]:
    folder = campaign.with_suffix(".certificates")
    return sorted(p.name for p in folder.glob("*") if p.suffix in (".html", ".pdf")) if folder.is_dir() else []


def _report(campaign: Path) -> Path | None:
    """A report `rig report` wrote for it: FILE.report/ beside it."""
    folder = campaign.with_suffix(".report")
    return folder if (folder / "index.html").is_file() else None


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    return value
