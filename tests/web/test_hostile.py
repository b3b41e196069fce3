"""The dashboard never shows a traceback: every route of the app (enumerated from `app.routes`: pages, JSON,
approval, the static mount), asked with each hostile path value and query string, GET and — where a route
takes it — POST, against a good registry, none, one that does not exist, a file that is not a database, one
of a newer schema, one that lost a table and one holding a date that is not a date, answers a status and
the dashboard's styled error page (`{"error": ...}` under /api/): no traceback, no exception's name, nothing
reflected unescaped, nothing created on disk, no exception reaching the server, one log line per 500. And the
attacks of issue 40: the same walk against a registry that never answers (an outage), a session replayed
after its user's logout, new password, new role or disabling (revocation), and a flood of wrong logins while
every page is asked."""

from __future__ import annotations

import hashlib
import logging
import re
import shutil
import socket
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from httpx import Response
from starlette.applications import Starlette
from starlette.routing import Mount, Route
from starlette.testclient import TestClient

from accelcal_rig.registry.approvals import Approvals, IssuedCertificate
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.live import campaign_key
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app
from accelcal_rig.web.registry_gate import PROBE_S

ORIGIN = {"origin": "http://127.0.0.1"}
#: Substituted, as written here (already percent-encoded), for one path parameter at a time.
HOSTILE = {
    "nul": "%00",
    "not-utf8": "%ff%fe",
    "traversal": "..%2f..%2fetc%2fpasswd",
    "long": "a" * 5000,
    "dots": "%2e%2e",
    "rtl-override": "%E2%80%AEfdp.exe",
    "script": "%3Cscript%3Ealert(1)%3C%2Fscript%3E",
    "empty": "",
    "unknown-number": "987654321",
    "beyond-a-row-id": "9" * 25,
}
QUERIES = [
    "made=%00", "made=%3Cscript%3Ealert(1)%3C%2Fscript%3E", "made=maybe", "serial=%ff%fe", "serial=%00",
    "serial=" + "a" * 3000, "serial=%E2%80%AE", "next=%2F%2Fevil.example", "next=%00",
    "message=%3Cscript%3Ealert(1)%3C%2Fscript%3E", "token=%00", "%ff=%fe", "a=" + "b" * 5000,
]
#: Hostile form bodies for the routes that take a POST: not UTF-8, NUL and script in every field, too long,
#: and one past the form's checks (CSRF: replaced by the session's token) with hostile fields.
BODIES = [b"\xff\xfe", b"csrf=%00&name=%3Cscript%3E&password=%00&next=%2F%2Fevil&action=%00&reason=%E2%80%AE",
          b"csrf=" + b"x" * 20_000,
          b"csrf=CSRF&name=%3Cscript%3E&password=" + b"p" * 500 + b"&next=%2F%2Fevil&action=%E2%80%AE&reason=" + b"r" * 5000]
#: Where a POST claims to come from: the dashboard itself, then addresses that are no address.
ORIGINS = ["http://127.0.0.1", "http://[", "http://127.0.0.1:99999%00"]
#: What names a Python exception, a traceback or the database library: never in a page.
LEAKS = re.compile(r"Traceback|\b[A-Z]\w*(?:Error|Exception)\b|sqlalchemy|sqlite3|psycopg")
STYLED = 'id="error-page"'
REGISTRY_KINDS = ["good", "none", "missing", "not-a-database", "newer-schema", "lost-a-table", "date-not-a-date"]
#: The good registry again, served with a token (sent as a header): no page may show it.
TOKEN = "t0ken-s3cret"
#: The approver's password in the lab's registry.
PASSWORD = "approver's secret"


@dataclass
class Lab:
    folder: Path                                  # the watched campaigns
    good: Path                                    # a registry holding the campaign, an approval, a certificate
    row_id: int                                   # ADX355-A001's calibration
    values: dict[str, str] = field(default_factory=dict)   # a valid value of each path parameter


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Lab:
    """A finished dry run, its certificates beside it, recorded in a registry with an approved calibration."""
    from accelcal_rig.cli import main
    from tests.conftest import REPO

    folder = tmp_path_factory.mktemp("campaigns")
    good = tmp_path_factory.mktemp("good") / "registry.sqlite"
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(folder / "quick.h5"),
                 "-q", "--no-pdf", "--registry", normalised(str(good))]) == 0
    book = Approvals(Registry.open(normalised(str(good))))
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    row_id = min(r["id"] for r in book.registry.calibrations(serial="ADX355-A001"))
    approver = book.user("jdoe")
    assert approver is not None
    book.record(row_id, "approve", approver, "test", certificate=IssuedCertificate(1, "N-1", "<p>1</p>", None))
    book.registry.engine.dispose()
    values = {"name": "quick.h5", "kind": "certificates", "file": "ADX355-A001.DRAFT.html", "serial": "ADX355-A001",
              "part": "adxl355", "id": str(row_id), "revision": "1", "path": "dashboard.css",
              "key": campaign_key(socket.gethostname(), str((folder / "quick.h5").resolve()))}  # the run published it
    return Lab(folder, good, row_id, values)


def registry_of(kind: str, lab: Lab, where: Path) -> str | None:
    """The URL of a registry of this kind, made with the real code and damaged with sqlite3."""
    path = where / "registry.sqlite"
    if kind == "none":
        return None
    if kind == "good, behind a token":
        kind = "good"
    if kind == "missing":
        return normalised(str(where / "absent" / "registry.sqlite"))
    if kind == "not-a-database":
        path.write_bytes(b"this is a text file, not a database\n" * 100)
        return normalised(str(path))
    shutil.copy(lab.good, path)
    damage = {"good": None,
              "newer-schema": "UPDATE alembic_version SET version_num = 'f0f0f0f0f0f0'",
              "lost-a-table": "DROP TABLE calibrations",
              # (its trigger keeps a decided calibration as it was: the damage is done past it)
              "date-not-a-date": "DROP TRIGGER calibrations_decided_update; "
                                 "UPDATE calibrations SET calibrated_at = 'not a date'"}[kind]
    if damage is not None:
        connection = sqlite3.connect(path)
        connection.executescript(damage)
        connection.commit()
        connection.close()
    return normalised(str(path))


def endpoints(app: Starlette) -> list[tuple[str, set[str]]]:
    """Every route's path template and methods, a mount's as `PATH/{path:path}`: a route of a kind this test
    does not know fails it (a new kind of route must be walked too)."""
    found = []
    for route in app.routes:
        if isinstance(route, Mount):
            found.append((route.path + "/{path:path}", {"GET"}))
        elif isinstance(route, Route):
            found.append((route.path, set(route.methods or {"GET"})))
        else:
            raise AssertionError(f"a route of a kind this test does not walk: {route!r}")
    return found


def parameters(template: str) -> list[str]:
    return re.findall(r"{(\w+)(?::\w+)?}", template)


def address(template: str, values: dict[str, str]) -> str:
    return re.sub(r"{(\w+)(?::\w+)?}", lambda m: values[m.group(1)], template)


def valid_values(template: str, lab: Lab) -> dict[str, str]:
    """Each parameter's valid value (a certificate revision's `kind` is its document type)."""
    values = {name: lab.values[name] for name in parameters(template)}  # a KeyError: a new parameter to add
    return values | ({"kind": "html"} if "{revision:int}.{kind}" in template else {})


Request = tuple[str, str, bytes | None, str]


def requests_of(app: Starlette, lab: Lab) -> list[Request]:
    """(method, address, body, origin) of the walk: every route GET with valid values, with each hostile
    value in each parameter, with each hostile query; and POSTed, where it takes it, with each hostile body
    from the dashboard's origin, and with a form's token from origins that are no address."""
    walk: list[Request] = []
    for template, methods in endpoints(app):
        valid = valid_values(template, lab)
        addresses = [address(template, valid)]
        addresses += [address(template, valid | {name: value}) for name in valid for value in HOSTILE.values()]
        walk += [("GET", a, None, ORIGINS[0]) for a in addresses]
        walk += [("GET", f"{addresses[0]}?{query}", None, ORIGINS[0]) for query in QUERIES]
        if "POST" in methods:
            walk += [("POST", a, body, ORIGINS[0]) for a in addresses for body in BODIES]
            walk += [("POST", addresses[0], BODIES[-1], origin) for origin in ORIGINS[1:]]
    return walk


@dataclass
class Walked:
    requests: int = 0
    statuses: dict[int, int] = field(default_factory=dict)
    failures: list[str] = field(default_factory=list)


def snapshot(*folders: Path) -> dict[str, str]:
    """Every file and folder under these, with its content's hash: what a request must leave as it was. A
    registry is compared by what it holds, the record of sign-ins left out (a failed login is recorded there,
    and counted against its user: registry/sign_ins.py); its write-ahead log and index go with it."""
    found = {}
    for folder in folders:
        for path in sorted(folder.rglob("*")):
            if path.name.endswith((".sqlite-wal", ".sqlite-shm")):
                continue
            if path.suffix == ".sqlite" and _is_sqlite(path):
                found[str(path)] = _registry_content(path)
                continue
            found[str(path)] = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "folder"
    return found


def _is_sqlite(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:16] == b"SQLite format 3\x00"


def _registry_content(path: Path) -> str:
    """A hash of every table's rows but the sign-in record's and a user's sign-in counters (read-only)."""
    import sqlite3

    digest = hashlib.sha256()
    connection = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    try:
        tables = [r[0] for r in connection.execute("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")]
        for table in tables:
            if table == "sign_ins":
                continue
            columns = [r[1] for r in connection.execute(f"PRAGMA table_info({table})")
                       if not (table == "users" and r[1] in ("failed_logins", "locked_until"))]
            rows = connection.execute(f"SELECT {', '.join(columns)} FROM {table} ORDER BY 1").fetchall()
            digest.update(repr((table, columns, rows)).encode())
    except sqlite3.DatabaseError as exc:  # a damaged registry the walk must leave as damaged as it was
        digest.update(repr(exc).encode() + path.read_bytes())
    finally:
        connection.close()
    return digest.hexdigest()


def problems(url: str, response: Response, new_log: list[logging.LogRecord], allowed: set[int]) -> list[str]:
    """What is wrong with one answer (nothing: an empty list)."""
    status = response.status_code
    found = [] if 200 <= status < 500 or status in allowed else ["a status not expected"]
    if status == 401 and 'action="/login"' not in response.text:  # the token middleware's refusal, as before
        return found + ([] if response.text.startswith("a token is needed") else ["a refusal that says more"])
    found += shown(response) + shape(url, response)
    logged = [r.getMessage() for r in new_log if r.levelno >= logging.ERROR]
    if (status == 500) != (len(logged) == 1) or any("\n" in line for line in logged):
        found.append(f"{len(logged)} lines logged for a {status}")
    return found


def shown(response: Response) -> list[str]:
    """What a body or a redirect must never show: the token, a traceback or an exception, a script."""
    found = ["shows the token"] if TOKEN in response.text + response.headers.get("location", "") else []
    if any(kind in response.headers.get("content-type", "") for kind in ("text/", "json")):
        if leak := LEAKS.search(response.text):
            found.append(f"shows {leak.group()!r}")
        if "<script>alert" in response.text:
            found.append("reflects a script unescaped")
    return found


def shape(url: str, response: Response) -> list[str]:
    """An error is the styled page, or under /api/ `{"error": ...}`."""
    status, kind = response.status_code, response.headers.get("content-type", "")
    if status < 400 or status == 401:
        return []
    if url.startswith("/api/"):
        return [] if "json" in kind and set(response.json()) == {"error"} else ["not the JSON error body"]
    styled = STYLED in response.text and f'data-status="{status}"' in response.text
    return [] if styled else [f"not the styled error page ({kind}: {response.text[:60]!r})"]


def walk(app: Starlette, lab: Lab, allowed: set[int], caplog: pytest.LogCaptureFixture,
         headers: dict[str, str]) -> Walked:
    """Every request of the walk on a client that raises whatever reaches the server."""
    client = TestClient(app, base_url="http://127.0.0.1", raise_server_exceptions=True,
                        headers=headers)
    done = Walked()
    for method, url, body, origin in requests_of(app, lab):
        if body is not None and b"CSRF" in body:
            body = body.replace(b"CSRF", session_token(client).encode())
        before = len(caplog.records)
        try:
            response = client.request(method, url, content=body, follow_redirects=False,
                                      headers={"origin": origin, "content-type": "application/x-www-form-urlencoded"}
                                      if body is not None else {})
        except Exception as exc:  # noqa: BLE001 - an exception that reached the server is the failure
            done.failures.append(f"{method} {url[:90]}: {type(exc).__name__} reached the server: {exc}")
            continue
        done.requests += 1
        done.statuses[response.status_code] = done.statuses.get(response.status_code, 0) + 1
        said = f"{method} {url[:90]} -> {response.status_code}"
        done.failures += [f"{said}: {problem}" for problem in problems(url, response, caplog.records[before:], allowed)]
    return done


def session_token(client: TestClient) -> str:
    """The session's form token, as the login page carries it."""
    found = re.search(r'name="csrf" value="([^"]+)"', client.get("/login").text)
    assert found is not None
    return found.group(1)


@pytest.mark.parametrize("kind", [*REGISTRY_KINDS, "good, behind a token"])
def test_every_route_answers_hostile_input_with_a_status_and_a_styled_page(
        kind: str, lab: Lab, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    url = registry_of(kind, lab, tmp_path)
    token = TOKEN if kind == "good, behind a token" else None
    app = create_app([lab.folder], url, token=token)
    headers = {"authorization": f"Bearer {TOKEN}"} if token else {}
    before = snapshot(lab.folder, tmp_path)
    # Until the registry layer says a row it cannot read in one line (a RigError), a date that is not a date
    # is an unforeseen error: the styled 500. Every other registry that cannot be read is a 503.
    allowed = set() if kind.startswith("good") else {503} | ({500} if kind == "date-not-a-date" else set())
    with caplog.at_level(logging.ERROR, logger="accelcal_rig.web"):
        done = walk(app, lab, allowed, caplog, headers)
    assert done.failures == [], f"{len(done.failures)} failures, e.g.\n" + "\n".join(done.failures[:15])
    assert snapshot(lab.folder, tmp_path) == before           # nothing created, nothing changed
    assert done.requests == len(requests_of(app, lab)) and set(done.statuses) >= {200, 400, 404, 405}
    expected = {"good": {200}, "good, behind a token": {200}, "date-not-a-date": {500, 503}}.get(kind, {503})
    client = TestClient(app, base_url="http://127.0.0.1", headers=headers)
    assert client.get("/registry").status_code in expected
    # A calibration the registry cannot read is not "no such calibration" (a 404): the registry's fault.
    assert client.get(f"/registry/calibrations/{lab.row_id}").status_code in expected


def test_every_route_is_walked(lab: Lab) -> None:
    """The walk covers the app's routes as they are: pages, JSON, approval, the static files."""
    app = create_app([lab.folder], None)
    templates = {template for template, _ in endpoints(app)}
    assert {"/", "/api/campaigns", "/campaigns/{name}/{kind}/{file:path}", "/registry/calibrations/{id:int}/decision",
            "/login", "/logout", "/api/registry/serials/{serial:path}", "/static/{path:path}"} <= templates
    walked = requests_of(app, lab)
    assert {url.split("?")[0] for _, url, _, _ in walked} >= {address(t, valid_values(t, lab)) for t in templates}
    assert any(method == "POST" and url.endswith("/decision") for method, url, _, _ in walked)


def test_a_get_never_creates_a_registry_and_a_later_one_is_seen(lab: Lab, tmp_path: Path) -> None:
    """A registry that does not exist (a cross-site GET once created it): a 503 page saying nothing is
    recorded yet, no file, no folder; once something is recorded, the next request shows it (a failure is
    kept beyond the next probe)."""
    url = normalised(str(tmp_path / "lab" / "registry.sqlite"))
    clock = [0.0]
    client = TestClient(create_app([lab.folder], url, clock=lambda: clock[0]), base_url="http://127.0.0.1")
    for path in ("/registry", "/registry/serials/ADX355-A001", f"/registry/calibrations/{lab.row_id}", "/login"):
        page = client.get(path)
        assert page.status_code in (200, 503) and not (tmp_path / "lab").exists()
    page = client.get("/registry")
    assert page.status_code == 503 and STYLED in page.text and "nothing recorded" in page.text
    api = client.get("/api/registry/serials/X")
    assert api.status_code == 503 and "nothing recorded" in api.json()["error"]
    (tmp_path / "lab").mkdir()
    shutil.copy(lab.good, tmp_path / "lab" / "registry.sqlite")
    assert client.get("/registry").status_code == 503          # known down: answered at once until the probe
    clock[0] += PROBE_S
    assert client.get("/registry").status_code == 200


def test_a_registry_damaged_while_served_is_503_and_seen_again_once_repaired(lab: Lab, tmp_path: Path) -> None:
    path = tmp_path / "registry.sqlite"
    shutil.copy(lab.good, path)
    clock = [0.0]
    client = TestClient(create_app([lab.folder], normalised(str(path)), clock=lambda: clock[0]),
                        base_url="http://127.0.0.1")
    assert client.get("/registry/serials/ADX355-A001").status_code == 200      # opened, kept
    shutil.copy(path, tmp_path / "kept.sqlite")
    connection = sqlite3.connect(path)
    connection.execute("DROP TABLE calibrations")
    connection.commit()
    connection.close()
    broken = client.get("/registry/serials/ADX355-A001")
    assert broken.status_code == 503 and STYLED in broken.text and "calibrations" in broken.text
    assert not LEAKS.search(broken.text)
    shutil.copy(tmp_path / "kept.sqlite", path)
    clock[0] += PROBE_S                                                          # the next probe finds it back
    assert client.get("/registry/serials/ADX355-A001").status_code == 200


def test_an_unforeseen_error_is_a_styled_500_and_one_line_on_the_log(
        lab: Lab, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    from accelcal_rig.web.campaigns import CampaignFolders

    def broken(self: CampaignFolders) -> list[dict]:
        raise KeyError("secret detail\nsecond line")

    monkeypatch.setattr(CampaignFolders, "summaries", broken)
    client = TestClient(create_app([lab.folder], None), base_url="http://127.0.0.1", raise_server_exceptions=True)
    with caplog.at_level(logging.ERROR, logger="accelcal_rig.web"):
        page, api = client.get("/"), client.get("/api/campaigns")
    assert page.status_code == 500 and STYLED in page.text and "internal error" in page.text
    assert 'class="where"' not in page.text          # (maybe before the token was checked: not even the registry)
    assert api.status_code == 500 and set(api.json()) == {"error"}
    for text in (page.text, api.text):
        assert "secret detail" not in text and "KeyError" not in text and "Traceback" not in text
    lines = [r.getMessage() for r in caplog.records if r.name == "accelcal_rig.web"]
    assert len(lines) == 2 and all("\n" not in line and "KeyError" in line and "GET '/'" in lines[0]
                                   for line in lines)


def test_error_pages_never_show_the_token(lab: Lab) -> None:
    """With a token, what cannot be served is the same page, without the token (which a query carried);
    without it, the refusal says nothing of the dashboard (plain text, as before)."""
    client = TestClient(create_app([lab.folder], None, token="t0ken-s3cret"), base_url="http://127.0.0.1")
    assert client.get("/registry").status_code == 401 and "registry" not in client.get("/registry").text
    for path in ("/campaigns/%00", "/campaigns/nothing.h5", "/nowhere", "/registry", "/api/campaigns/x"):
        answer = client.get(path, params={"token": "t0ken-s3cret"})
        assert answer.status_code in (400, 404, 503) and "t0ken-s3cret" not in answer.text


def test_the_forms_refusals_are_styled_and_unchanged(lab: Lab, tmp_path: Path) -> None:
    """Approval's refusals keep their statuses and messages, now on the error page."""
    path = tmp_path / "registry.sqlite"
    shutil.copy(lab.good, path)
    client = TestClient(create_app([lab.folder], normalised(str(path))), base_url="http://127.0.0.1")
    decide = f"/registry/calibrations/{lab.row_id}/decision"
    refused = client.post(decide, data={"action": "approve"}, headers={"origin": "http://evil.example"})
    assert refused.status_code == 403 and STYLED in refused.text and "another site" in refused.text
    stale = client.post(decide, data={"csrf": "forged", "action": "approve"}, headers=ORIGIN)
    assert stale.status_code == 403 and "missing or stale" in stale.text
    assert client.post("/login", content=b"csrf=" + b"x" * 20_000, headers=ORIGIN).status_code == 413
    assert client.get("/logout").status_code == 405 and STYLED in client.get("/logout").text


def _signed_in_client(app: Starlette, address: str) -> TestClient:
    client = TestClient(app, base_url="http://127.0.0.1", client=(address, 50000))
    answer = client.post("/login", data={"csrf": session_token(client), "name": "jdoe", "password": PASSWORD},
                         headers=ORIGIN, follow_redirects=False)
    assert answer.status_code == 303 and "Signed in as Jane Doe" in client.get("/login").text
    return client


@pytest.mark.parametrize("revoke", ["logout elsewhere", "password changed", "role changed", "disabled"])
def test_a_revoked_session_decides_nothing_on_any_route(revoke: str, lab: Lab, tmp_path: Path) -> None:
    """Revocation: a session its user's logout (from another browser), a new password, another role or disabling
    ended, replayed with its cookie and its form token on every route that changes something and every page:
    no page shows it signed in, no decision is taken, the registry holds what it held."""
    path = tmp_path / "registry.sqlite"
    shutil.copy(lab.good, path)
    app = create_app([lab.folder], normalised(str(path)))
    stolen, other = _signed_in_client(app, "10.1.0.1"), _signed_in_client(app, "10.1.0.2")
    form_token = session_token(stolen)
    book = Approvals(Registry.open(normalised(str(path))))
    if revoke == "logout elsewhere":
        assert other.post("/logout", data={"csrf": session_token(other)}, headers=ORIGIN).status_code == 200
    else:
        {"password changed": lambda: book.set_password("jdoe", "a new secret!"),
         "role changed": lambda: book.set_role("jdoe", "viewer"),
         "disabled": lambda: book.set_disabled("jdoe", True)}[revoke]()
    before = snapshot(tmp_path)
    for template, methods in endpoints(app):
        url = address(template, valid_values(template, lab))
        page = stolen.get(url)
        assert "Signed in as" not in page.text and "Jane Doe</strong>" not in page.text, url
        if "POST" in methods and template != "/login":
            for action in ("approve", "reject", "reissue"):
                answer = stolen.post(url, data={"csrf": form_token, "action": action, "password": PASSWORD,
                                                "reason": "replayed"}, headers=ORIGIN, follow_redirects=False)
                assert answer.status_code in (200, 303, 403), (url, answer.status_code)
    assert snapshot(tmp_path) == before                       # nothing decided, nothing issued
    assert [t for t in book.trail(calibration_id=lab.row_id) if t["reason"] == "replayed"] == []


def test_a_login_flood_holds_up_no_page_and_ends_in_a_lockout_the_record_keeps(lab: Lab, tmp_path: Path) -> None:
    """A flood: forty wrong logins at once — the approver's name from many clients, names no user has, one
    client again and again — while every page is asked with its valid values. Each page answers as it does
    without the flood (within a deadline a queue behind the hashes would miss); each login a styled 401, 429
    with Retry-After, or a 503 busy; the approver's account is locked with every failure recorded, and then
    even the right password waits for the lockout."""
    import anyio
    import httpx

    from accelcal_rig.registry.sign_ins import ACCOUNT_FAILURES, SignIns

    path = tmp_path / "registry.sqlite"
    shutil.copy(lab.good, path)
    url = normalised(str(path))
    app = create_app([lab.folder], url)
    pages = [address(t, valid_values(t, lab)) for t, methods in endpoints(app) if "GET" in methods]
    calm = TestClient(app, base_url="http://127.0.0.1")
    expected = {page: calm.get(page).status_code for page in pages}
    answers: list[httpx.Response] = []
    served: dict[str, int] = {}

    async def flood() -> None:
        async def client(address_: str) -> httpx.AsyncClient:
            return httpx.AsyncClient(transport=httpx.ASGITransport(app=app, client=(address_, 50000)),
                                     base_url="http://127.0.0.1")

        async def wrong_login(address_: str, name: str) -> None:
            async with await client(address_) as browser:
                found = re.search(r'name="csrf" value="([^"]+)"', (await browser.get("/login")).text)
                assert found is not None
                answers.append(await browser.post("/login", headers=ORIGIN, data={
                    "csrf": found.group(1), "name": name, "password": "guess"}))

        async def page(url_: str) -> None:
            async with await client("10.2.9.9") as browser:
                served[url_] = (await browser.get(url_)).status_code

        with anyio.fail_after(120):                # a deadline: the flood's hashes alone would take seconds
            async with anyio.create_task_group() as group:
                for k in range(40):
                    address_, name = [(f"10.2.0.{k}", "jdoe"), (f"10.2.1.{k}", f"nobody{k % 3}"),
                                      ("10.2.2.1", f"guess{k}")][k % 3]
                    group.start_soon(wrong_login, address_, name)
                for url_ in pages:
                    group.start_soon(page, url_)

    anyio.run(flood)
    assert served == expected
    assert len(answers) == 40 and {a.status_code for a in answers} <= {401, 429, 503}
    assert any(a.status_code == 429 for a in answers)
    for answer in answers:
        assert not shown(answer)
        if answer.status_code == 401:                          # the login form again, saying why
            assert 'action="/login"' in answer.text and "unknown user or wrong password" in answer.text
        else:
            assert STYLED in answer.text and int(answer.headers["retry-after"]) > 0
    record = SignIns(Registry.open(url)).record("jdoe")
    events = [e["event"] for e in record]               # (checks already under way when it locked are recorded too)
    assert events.count("login failed") >= ACCOUNT_FAILURES and "locked" in events
    right = TestClient(app, base_url="http://127.0.0.1", client=("10.2.3.1", 50000))
    locked = right.post("/login", data={"csrf": session_token(right), "name": "jdoe", "password": PASSWORD},
                        headers=ORIGIN)
    assert locked.status_code == 429 and "locked after too many failed logins" in locked.text


def test_a_silent_registry_answers_every_route_with_a_status_and_a_styled_page(
        lab: Lab, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """An outage: a PostgreSQL registry that accepts connections and never answers. The whole walk — every route,
    every hostile value — is answered (503 where the registry is needed, styled, nothing reflected), and once
    the first request found it silent no other one waits on it: it is known down until a probe (the probes'
    clock stands still here), so the walk opens no second connection."""
    pytest.importorskip("psycopg")
    from tests.web.test_registry_outage import SilentServer

    server = SilentServer()
    try:
        url = f"postgresql://lab@127.0.0.1:{server.port}/registry"
        app = create_app([lab.folder], url, clock=lambda: 0.0)
        before = snapshot(lab.folder, tmp_path)
        with caplog.at_level(logging.ERROR, logger="accelcal_rig.web"):
            done = walk(app, lab, {503}, caplog, {})
        assert done.failures == [], f"{len(done.failures)} failures, e.g.\n" + "\n".join(done.failures[:15])
        assert done.requests == len(requests_of(app, lab)) and done.statuses.get(503, 0) >= 50
        assert len(server.accepted) == 1                       # tried once; known down for the rest of the walk
        assert snapshot(lab.folder, tmp_path) == before
    finally:
        server.close()
