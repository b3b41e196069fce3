"""The dashboard's approval: a calibration's page (its decision, the record of decisions, every certificate
revision issued) and, for an authenticated approver, approve, reject and reissue.

Who is an approver: a registry user with the approver role, known by their password (a login form; a
session cookie signed with a key made at each start, HttpOnly, SameSite=Strict) or by the lab's reverse
proxy (`rig serve --user-header NAME`: the proxy authenticated them and names them in that header; the proxy
must strip it from what clients send). Logins are limited per client and per account and recorded
(web/sign_in.py, registry/sign_ins.py); a session ends at logout, when its user's password, role or state
changes (every session of theirs at once), after 30 idle minutes and 8 hours after its login; a decision
asks for the password again. Every state-changing request is a POST that carries the session's token and
comes from the dashboard's own origin (Origin, else Referer): a page elsewhere cannot approve in the
approver's name. Everything else on the dashboard is read-only as before.
"""

from __future__ import annotations

import hmac
import re
import secrets
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any, cast
from urllib.parse import parse_qs, urlsplit

from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import HTMLResponse, RedirectResponse, Response
from starlette.routing import Route

from accelcal_rig.errors import RigError
from accelcal_rig.registry.approvals import Action, Approvals, User
from accelcal_rig.registry.sign_ins import SignIns
from accelcal_rig.web.registry_gate import RegistryReadOnly
from accelcal_rig.web.sign_in import Busy, SignInPolicy

#: A login or decision form is a few hundred bytes; anything much longer is refused unread.
MAX_FORM_BYTES = 16_384
SESSION_USER = "user"
#: The session's user's generation at login, when it began, when it was last used (registry/sign_ins.py).
SESSION_GENERATION, SESSION_SINCE, SESSION_SEEN = "generation", "since", "seen"
#: A message for the next page the session shows (after an action: never one a link sets).
SESSION_MESSAGE = "message"
#: Set by the token middleware when the token came as an Authorization header: the reverse proxy's request.
BEARER_SCOPE_KEY = "accelcal.bearer"
#: The largest row id a database holds (a longer number in a path is no calibration).
MAX_ID = 2**63 - 1
SESSION_TOKEN = "csrf"
#: How the registry says a calibration or a certificate revision is not there; anything else it says of one
#: (a row it cannot read) is a registry that cannot be read: the 503 page, not a 404.
_NOT_THERE = re.compile(r": (?:no calibration \d+|calibration \d+ has no certificate revision \d+)$")


class ApprovalSettings:
    def __init__(self, user_header: str | None, policy: SignInPolicy | None = None) -> None:
        self.user_header = user_header
        policy = policy or SignInPolicy()
        self.sessions, self.limits, self.utc_now = policy.sessions, policy.limits, policy.utc_now

    def authority(self, user: User, via_header: bool) -> str:
        return (f"dashboard, reverse proxy header {self.user_header}" if via_header
                else f"dashboard, password of registry user {user.name}")


def approval_routes(registry: Any, page: Callable[..., HTMLResponse], settings: ApprovalSettings) -> list[Route]:
    """`registry`: the dashboard's lazily opened registry (its `get()`)."""

    def approvals() -> Approvals:
        return Approvals(registry.get())

    def current_user(request: Request) -> tuple[User | None, bool]:
        """The approver this request is from, and whether the reverse proxy named them. A session whose user
        was since disabled, changed or logged out everywhere (their generation raised), or left idle or kept
        beyond its lifetime, is ended here."""
        if settings.user_header:  # only the proxy, known by the token it sends as a header, names a user
            name = request.headers.get(settings.user_header, "") if request.scope.get(BEARER_SCOPE_KEY) else ""
            user = approvals().user(name) if name else None
            return (user if user is not None and not user.disabled else None), True
        remembered = request.session.get(SESSION_USER)
        if not isinstance(remembered, str):
            return None, False
        user = approvals().user(remembered)
        session = request.session
        if (user is None or user.disabled or session.get(SESSION_GENERATION) != user.generation
                or not settings.sessions.alive(session.get(SESSION_SINCE), session.get(SESSION_SEEN))):
            session.clear()
            return None, False
        session[SESSION_SEEN] = settings.sessions.clock()
        return user, False

    async def writable() -> None:
        """A login or a decision writes to the registry: refused (409, saying why) where it is read-only."""
        try:
            await registry.call(registry.writable)
        except RegistryReadOnly as exc:
            raise HTTPException(409, f"refused: {exc}") from None

    def token(request: Request) -> str:
        if SESSION_TOKEN not in request.session:
            request.session[SESSION_TOKEN] = secrets.token_urlsafe(32)
        return str(request.session[SESSION_TOKEN])

    async def form(request: Request) -> dict[str, str]:
        """The posted form, once its origin and token are checked; else the refusal (HTTPException: the
        dashboard's error page)."""
        if not same_origin(request):
            raise HTTPException(403, "refused: a request from another site (Origin)")
        body = b""
        async for chunk in request.stream():
            body += chunk
            if len(body) > MAX_FORM_BYTES:
                raise HTTPException(413, "refused: form too large")
        try:
            fields = {k: v[0] for k, v in parse_qs(body.decode("utf-8"), strict_parsing=False).items()}
        except UnicodeDecodeError:
            raise HTTPException(400, "refused: a form that is not UTF-8") from None
        if any("\x00" in k or "\x00" in v for k, v in fields.items()):
            raise HTTPException(400, "refused: a form with a NUL character")
        expected = request.session.get(SESSION_TOKEN)
        if not isinstance(expected, str) or not hmac.compare_digest(fields.get("csrf", "").encode(), expected.encode()):
            raise HTTPException(403, "refused: the form's token is missing or stale: reload the page")
        return fields

    def login_page(request: Request) -> Response:
        target = request.query_params.get("next", "/registry")
        user = current_user(request)[0] if not settings.user_header else None
        return page("login.html", csrf=token(request), error="", proxy=settings.user_header,
                    next=target if _local(target) else "/registry", user=user)

    async def login(request: Request) -> Response:
        if settings.user_header:
            raise HTTPException(404, "the reverse proxy authenticates users here")
        fields = await form(request)
        await writable()
        name, target = fields.get("name", "")[:200], fields.get("next", "/registry")
        user = await checked_password(request, name, fields.get("password", ""))
        if user is None:
            return page("login.html", csrf=token(request), error="unknown user or wrong password", proxy=None,
                        next=target, status=401)
        await registry.call(lambda: SignIns(registry.get()).signed_in(user.name, client_of(request), settings.utc_now()))
        request.session.clear()  # a new session for the person: no fixation of an earlier one
        request.session.update({SESSION_USER: user.name, SESSION_GENERATION: user.generation,
                                SESSION_SINCE: settings.sessions.clock(), SESSION_SEEN: settings.sessions.clock(),
                                SESSION_TOKEN: secrets.token_urlsafe(32)})
        return RedirectResponse(target if _local(target) else "/registry", status_code=303)

    async def checked_password(request: Request, name: str, password: str) -> User | None:
        """The user whose password this is, or None (a failed login, recorded and counted against the client
        and the name); refused with 429 and Retry-After while either is locked out, before any hashing."""
        limits, client = settings.limits, client_of(request)
        wait_s = limits.clients.retry_after_s(client)
        if wait_s > 0:
            raise _too_many(f"too many failed logins from {client}", wait_s)
        known = await registry.call(lambda: approvals().user(name)) is not None
        locked_s = (await registry.call(lambda: SignIns(registry.get()).locked_for_s(name, settings.utc_now()))
                    if known else limits.unknown_names.retry_after_s(name))
        if locked_s > 0:
            raise _too_many("this account is locked after too many failed logins", locked_s)
        try:
            user = await limits.hashing.run(lambda: approvals().authenticate(name, password))
        except Busy:
            raise HTTPException(503, "busy checking other logins: try again in a few seconds",
                                headers={"Retry-After": "5"}) from None
        if user is not None:
            # Checks run two at a time: a right password checked while wrong ones locked the account is refused.
            locked_s = await registry.call(lambda: SignIns(registry.get()).locked_for_s(name, settings.utc_now()))
            if locked_s > 0:
                raise _too_many("this account is locked after too many failed logins", locked_s)
            limits.unknown_names.forget(name)
            return user
        limits.clients.failed(client)
        locked_s = await registry.call(lambda: SignIns(registry.get()).failed(name, client, settings.utc_now()))
        if not known:
            locked_s = limits.unknown_names.failed(name)
        if locked_s > 0:
            raise _too_many("this account is locked after too many failed logins", locked_s)
        return None

    async def logout(request: Request) -> Response:
        await form(request)
        name = request.session.get(SESSION_USER)
        request.session.clear()
        if isinstance(name, str) and not registry.read_only:  # every session of theirs ends, this and any other
            await registry.call(lambda: SignIns(registry.get()).end_sessions(name, client_of(request),
                                                                             settings.utc_now(), "logout"))
        return RedirectResponse("/registry", status_code=303)

    def calibration_page(request: Request) -> Response:
        row_id = int(request.path_params["id"])
        if row_id > MAX_ID:
            raise HTTPException(404, "no such calibration in the registry")
        reg = registry.get()
        try:
            row = reg.calibration(row_id)
        except RigError as exc:
            raise _not_there(exc, f"no calibration {row_id} in the registry") from None
        book = approvals()
        user, via_header = current_user(request)
        return page("calibration.html", row=row, decision=book.decision(row_id), trail=book.trail(calibration_id=row_id),
                    certificates=book.certificates(row_id), user=user, via_header=via_header,
                    csrf=token(request), campaign_here=_campaign_of(row) is not None,
                    message=str(request.session.pop(SESSION_MESSAGE, "")))

    async def decide(request: Request) -> Response:
        row_id = int(request.path_params["id"])
        if row_id > MAX_ID:
            raise HTTPException(404, "no such calibration in the registry")
        fields = await form(request)
        await writable()
        user, via_header = await registry.call(current_user, request)
        if user is None or not user.may_approve:
            raise HTTPException(403, "refused: log in as an approver")
        action = fields.get("action", "")
        if action not in ("approve", "reject", "reissue"):
            raise HTTPException(400, f"action {action[:40]!r}: not one of approve, reject, reissue")
        # A reissue's amendments: a field left empty is not amended.
        amendments: dict[str, str | None] = {key: fields.get(field, "").strip() or None for key, field in (
            ("customer", "customer"), ("contact", "contact"), ("received_date", "received"),
            ("condition", "condition"), ("remarks", "remarks"))} if action == "reissue" else {}
        # A decision is signed with the password again (a session left open is not a signature); a reverse
        # proxy's user re-authenticates as the proxy asks, which is the proxy's to decide.
        if not via_header and await checked_password(request, user.name, fields.get("password", "")) is None:
            raise HTTPException(403, "refused: the password is wrong: nothing was decided")
        try:
            # Not a bounded registry call: rendering the certificate takes its time (the registry's own
            # timeouts bound its part).
            message = await run_in_threadpool(lambda: _decide(registry.get(), row_id, cast(Action, action), user,
                                                              settings.authority(user, via_header),
                                                              fields.get("reason", ""), amendments))
        except RigError as exc:
            raise HTTPException(409, f"refused: {exc}") from None
        except OSError as exc:  # the campaign or its calibration unreadable here: one line, nothing recorded
            raise HTTPException(409, f"refused: {exc.filename or 'a file'}: {exc.strerror or exc}") from None
        request.session[SESSION_MESSAGE] = message[:300]
        return RedirectResponse(f"/registry/calibrations/{row_id}", status_code=303)

    def certificate_file(request: Request) -> Response:
        row_id, revision, kind = (int(request.path_params["id"]), int(request.path_params["revision"]),
                                  request.path_params["kind"])
        if row_id > MAX_ID or revision > MAX_ID:
            raise HTTPException(404, "no such certificate revision")
        if kind not in ("pdf", "html"):  # the address checked before the registry is read
            raise HTTPException(404, "no such certificate file")
        try:
            row = approvals().certificate(row_id, revision)
        except RigError as exc:
            raise _not_there(exc, "no such certificate revision") from None
        if kind == "html":
            return HTMLResponse(row["html"], headers={"Content-Security-Policy": "sandbox"})  # see app.SANDBOXED
        if row["pdf"] is None:
            raise HTTPException(404, "issued as HTML only")
        return Response(bytes(row["pdf"]), media_type="application/pdf")

    def draft_row(request: Request) -> dict[str, Any]:
        row_id = int(request.path_params["id"])
        if row_id > MAX_ID:
            raise HTTPException(404, "no such calibration in the registry")
        try:
            return registry.get().calibration(row_id)  # type: ignore[no-any-return]
        except RigError as exc:
            raise _not_there(exc, f"no calibration {row_id} in the registry") from None

    async def draft(request: Request) -> Response:
        """The draft certificate of a calibration whose campaign is on this computer, as the files make it now
        (HTML, sandboxed as every page the dashboard did not write itself): what the approver reads first. The
        registry is asked for the row only; the campaign is read outside the registry's turns (a large campaign
        takes its time, which is not the registry's)."""
        row = await registry.call(draft_row, request)
        found = _campaign_of(row)
        if found is None:
            raise HTTPException(404, f"the campaign file of calibration {row['id']} is not on this computer")
        from accelcal_rig.report.certificate import draft_html

        try:
            page = await run_in_threadpool(draft_html, found[0], found[1], str(row["serial"]))
        except (RigError, OSError) as exc:
            raise HTTPException(409, f"no draft: {str(exc).splitlines()[0]}") from None
        return HTMLResponse(page, headers={"Content-Security-Policy": "sandbox"})

    def gated(handler: Callable[[Request], Response]) -> Callable[[Request], Awaitable[Response]]:
        async def endpoint(request: Request) -> Response:
            return await registry.call(handler, request)  # type: ignore[no-any-return]
        return endpoint

    return [Route("/login", gated(login_page), methods=["GET"]), Route("/login", login, methods=["POST"]),
            Route("/logout", logout, methods=["POST"]),
            Route("/registry/calibrations/{id:int}", gated(calibration_page), methods=["GET"]),
            Route("/registry/calibrations/{id:int}/decision", decide, methods=["POST"]),
            Route("/registry/calibrations/{id:int}/draft", draft, methods=["GET"]),
            Route("/registry/calibrations/{id:int}/certificates/{revision:int}.{kind}", gated(certificate_file))]


def same_origin(request: Request) -> bool:
    """Whether a state-changing request comes from the dashboard's own pages: its Origin (else its Referer)
    names the scheme, host and port the request was sent to."""
    claimed = request.headers.get("origin") or request.headers.get("referer")
    if not claimed or claimed == "null":
        return False
    try:
        parts = urlsplit(claimed)
    except ValueError:  # not an address at all ("http://[")
        return False
    own = urlsplit(str(request.base_url))
    return (parts.scheme, parts.netloc) == (own.scheme, own.netloc)


def client_of(request: Request) -> str:
    """The client's address as the server saw it (behind a reverse proxy: the proxy's, unless the server was
    told to trust its forwarded header)."""
    return request.client.host if request.client is not None else "unknown"


def _too_many(why: str, wait_s: float) -> HTTPException:
    """429 with Retry-After (whole seconds, at least 1)."""
    seconds = max(1, int(wait_s + 0.999))
    return HTTPException(429, f"refused: {why}: try again in {seconds // 60} min {seconds % 60} s",
                         headers={"Retry-After": str(seconds)})


def _not_there(exc: RigError, message: str) -> Exception:
    """What to raise for the registry's refusal: a 404 if it said the row is not there, else the refusal
    itself (a registry that cannot be read, answered 503)."""
    return HTTPException(404, message) if _NOT_THERE.search(str(exc)) else exc


def _local(target: str) -> bool:
    """A redirect target on this dashboard (a path, not another site's address)."""
    return target.startswith("/") and not target.startswith("//") and "\\" not in target


def _campaign_of(row: dict[str, Any]) -> tuple[Path, Path] | None:
    """The campaign file and its calibration file on this computer, as recorded, if both are here."""
    if row["source_kind"] != "campaign":
        return None
    campaign = Path(row["source_path"])
    calibration = campaign.with_suffix(".calibration.yaml")
    return (campaign, calibration) if campaign.is_file() and calibration.is_file() else None


def _decide(reg: Any, row_id: int, action: Action, user: User, authority: str, reason: str,
            given: dict[str, str | None]) -> str:
    """Record the decision; an approval or a reissue renders the certificate revision from the campaign (a
    reissue with the amendments `given`: None for each not amended)."""
    from accelcal_rig.registry.entries import campaign_entries
    from accelcal_rig.report.certificate import certificates_folder, write_issued
    from accelcal_rig.web.issuing import issued_certificate

    book = Approvals(reg)
    row = reg.calibration(row_id)
    issued, found, at = None, None, None
    if action != "reject":
        found = _campaign_of(row)
        if found is None:
            raise RigError(f"the campaign file {row['source_path']} (and its calibration beside it) is not on this "
                           "computer: approve with rig approve where it is")
        if action == "approve" and book.decision(row_id).state == "approved":
            raise RigError("approved already: a new revision is a reissue, with a reason")
        # The certificate must be of the fit decided on: the campaign and the calibration beside it now make
        # the same registry rows, or the files have changed (a refit) since it was recorded.
        lead = book.rows_of(row_id)[0]
        if reg.ids_of(campaign_entries(*found)).get(row["serial"]) != lead["id"]:
            raise RigError(f"{found[1].name} beside the campaign is not the fit of calibration {lead['id']} (refitted "
                           "since?): approve the calibration it is, or fit again and record it")
        issued, at = issued_certificate(book, int(lead["id"]), str(row["serial"]), action, user, authority, reason,
                                        found[0], found[1], given)
    revision_issued = book.record(row_id, action, user, authority, reason, issued, at)
    if issued is None or found is None:
        return f"{action}d by {user.full_name}"
    said = f"{action}d by {user.full_name}: certificate {issued.number} revision {revision_issued} issued"
    try:  # where the run's certificates are, as rig approve writes it; the registry keeps it either way
        written = write_issued(certificates_folder(found[0]), row["serial"], issued.revision, issued.html, issued.pdf)
    except OSError as exc:
        return f"{said} (kept in the registry; not written beside the campaign: {exc.strerror or exc})"
    return f"{said} → {', '.join(p.name for p in written)}"
