"""Sign-ins on the dashboard: sessions end when they must (logout ends every session of the user, as do a new
password, another role and disabling; an idle or an old session ends by itself), logins are limited per account
(a lockout in the registry, lifted by time or `enable`) and per client, names no user has are limited alike,
every failure is in the record, and a password check never holds up another request."""

from __future__ import annotations

import re
import threading
from datetime import datetime, timedelta
from pathlib import Path

import anyio
import httpx
import pytest
from starlette.testclient import TestClient

from accelcal_rig.registry.approvals import Approvals
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from accelcal_rig.registry.sign_ins import ACCOUNT_FAILURES, LOCKOUT_S, SignIns
from accelcal_rig.web.app import create_app
from accelcal_rig.web.sign_in import CLIENT_FAILURES, SessionPolicy, SignInLimits, SignInPolicy

PASSWORD = "approver's secret"
ORIGIN = {"origin": "http://127.0.0.1"}


class Clocks:
    """The wall clock sessions read, the monotonic one the client limits read, and the registry's UTC."""

    def __init__(self) -> None:
        self.wall_s, self.utc = 1_000_000.0, datetime(2026, 12, 7, 8, 0, 0)

    def advance(self, seconds: float) -> None:
        self.wall_s += seconds
        self.utc += timedelta(seconds=seconds)

    def policy(self) -> SignInPolicy:
        return SignInPolicy(SessionPolicy(clock=lambda: self.wall_s), SignInLimits.create(clock=lambda: self.wall_s),
                            lambda: self.utc)


@pytest.fixture
def lab(tmp_path: Path) -> tuple[Path, str, Clocks]:
    registry = normalised(str(tmp_path / "registry.sqlite"))
    book = Approvals(Registry.open(registry))
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    return tmp_path, registry, Clocks()


def _client(lab: tuple[Path, str, Clocks], app=None, address: str = "10.0.0.1") -> TestClient:
    folder, registry, clocks = lab
    return TestClient(app or create_app([folder], registry, sign_in=clocks.policy()), base_url="http://127.0.0.1",
                      client=(address, 50000))


def _csrf(client: TestClient) -> str:
    found = re.search(r'name="csrf" value="([^"]+)"', client.get("/login").text)
    assert found is not None
    return found.group(1)


def _login(client: TestClient, name: str = "jdoe", password: str = PASSWORD) -> httpx.Response:
    return client.post("/login", data={"csrf": _csrf(client), "name": name, "password": password}, headers=ORIGIN,
                       follow_redirects=False)


def _signed_in(client: TestClient) -> bool:
    return "Signed in as Jane Doe" in client.get("/login").text


def test_logout_ends_every_session_of_the_user_and_a_replayed_cookie_is_out(lab) -> None:
    app = create_app([lab[0]], lab[1], sign_in=lab[2].policy())
    here, there = _client(lab, app), _client(lab, app, "10.0.0.2")
    assert _login(here).status_code == 303 and _login(there).status_code == 303
    assert _signed_in(here) and _signed_in(there)
    kept = dict(here.cookies)                          # what an attacker copied before the logout
    assert here.post("/logout", data={"csrf": _csrf(here)}, headers=ORIGIN).status_code == 200
    assert not _signed_in(here) and not _signed_in(there)
    replay = _client(lab, app, "10.0.0.3")
    replay.cookies.update(kept)
    assert not _signed_in(replay)
    events = [e["event"] for e in SignIns(Registry.open(lab[1])).record("jdoe")]
    assert events == ["login", "login", "logout"]


@pytest.mark.parametrize(("change", "why"), [
    (lambda book: book.set_password("jdoe", "a new secret!"), "password changed"),
    (lambda book: book.set_role("jdoe", "viewer"), "role changed to viewer"),
    (lambda book: book.set_disabled("jdoe", True), "disabled"),
])
def test_a_change_to_the_user_ends_their_sessions(lab, change, why) -> None:
    client = _client(lab)
    assert _login(client).status_code == 303 and _signed_in(client)
    change(Approvals(Registry.open(lab[1])))
    assert not _signed_in(client)
    (ended,) = [e for e in SignIns(Registry.open(lab[1])).record("jdoe") if e["event"] == "sessions ended"]
    assert ended["detail"] == why and ended["client"] == "command line"


def test_a_session_ends_when_idle_and_when_old(lab) -> None:
    clocks = lab[2]
    client = _client(lab)
    assert _login(client).status_code == 303
    for _ in range(16):                                # 16 × 29 min: used within 30 min each time, 7.7 h in all
        clocks.advance(29 * 60)
        assert _signed_in(client)
    clocks.advance(29 * 60)                            # 8.2 h after its login
    assert not _signed_in(client)
    assert _login(client).status_code == 303
    clocks.advance(31 * 60)                            # left idle
    assert not _signed_in(client)


def test_failed_logins_lock_the_account_until_time_or_enable_lifts_it(lab) -> None:
    clocks = lab[2]
    client = _client(lab)
    for _ in range(ACCOUNT_FAILURES - 1):
        assert _login(client, password="guess").status_code == 401
    locked = _login(client, password="guess")
    assert locked.status_code == 429 and int(locked.headers["retry-after"]) == LOCKOUT_S
    right = _login(_client(lab, address="10.0.0.9"), password=PASSWORD)   # from anywhere, even the right one
    assert right.status_code == 429 and "locked after too many failed logins" in right.text
    record = SignIns(Registry.open(lab[1])).record("jdoe")
    assert [e["event"] for e in record] == ["login failed"] * ACCOUNT_FAILURES + ["locked"]
    assert all(e["client"] == "10.0.0.1" for e in record)
    clocks.advance(LOCKOUT_S + 1)                      # lifted by time
    assert _login(_client(lab, address="10.0.0.9")).status_code == 303
    for _ in range(ACCOUNT_FAILURES):
        _login(_client(lab, address="10.0.0.8"), password="guess")
    assert _login(_client(lab, address="10.0.0.7")).status_code == 429
    Approvals(Registry.open(lab[1])).set_disabled("jdoe", False)   # rig registry user enable
    assert SignIns(Registry.open(lab[1])).locked_for_s("jdoe", clocks.utc) == 0   # (the registry's own clock)
    assert _login(_client(lab, address="10.0.0.7")).status_code == 303


def test_names_no_user_has_are_locked_alike_and_recorded(lab) -> None:
    app = create_app([lab[0]], lab[1], sign_in=lab[2].policy())   # kept by the dashboard, not the registry
    for _ in range(ACCOUNT_FAILURES - 1):
        assert _login(_client(lab, app, "10.0.1.1"), name="nobody", password="guess").status_code == 401
    locked = _login(_client(lab, app, "10.0.1.2"), name="nobody", password="guess")
    assert locked.status_code == 429 and "locked after too many failed logins" in locked.text
    assert _login(_client(lab, app, "10.0.1.3"), name="nobody", password="guess").status_code == 429
    assert [e["event"] for e in SignIns(Registry.open(lab[1])).record("nobody")] == ["login failed"] * ACCOUNT_FAILURES


def test_one_client_failing_again_and_again_is_held_off_and_others_are_not(lab) -> None:
    app = create_app([lab[0]], lab[1], sign_in=lab[2].policy())
    flood = _client(lab, app, "10.0.2.1")
    answers = [_login(flood, name=f"name{k}", password="guess").status_code for k in range(CLIENT_FAILURES + 1)]
    assert answers == [401] * CLIENT_FAILURES + [429]
    assert _login(flood).status_code == 429             # the right password too, from that client
    assert _login(_client(lab, app, "10.0.2.2")).status_code == 303
    lab[2].advance(11 * 60)
    assert _login(flood).status_code == 303


def test_a_decision_on_the_dashboard_asks_for_the_password_and_counts_a_wrong_one(lab) -> None:
    client = _client(lab)
    assert _login(client).status_code == 303
    decide = "/registry/calibrations/1/decision"
    wrong = client.post(decide, data={"csrf": _csrf(client), "action": "approve", "password": "guess"}, headers=ORIGIN)
    assert wrong.status_code == 403 and "password is wrong" in wrong.text
    right = client.post(decide, data={"csrf": _csrf(client), "action": "approve", "password": PASSWORD}, headers=ORIGIN)
    assert right.status_code == 404 or right.status_code == 409   # past the password: the registry has no such row
    assert [e["event"] for e in SignIns(Registry.open(lab[1])).record("jdoe")] == ["login", "login failed"]


def test_a_message_after_an_action_comes_from_the_session_not_the_address(lab) -> None:
    client = _client(lab)
    page = client.get("/login?message=%3Cb%3Eapproved%20by%20the%20director%3C%2Fb%3E")
    assert "approved by the director" not in page.text


def test_password_checks_run_off_the_event_loop(lab, monkeypatch) -> None:
    """While every password check is held (each waits for a signal a test gives), a static file, the login page and
    a campaign page are served: nothing waits for a hash."""
    release, started = threading.Event(), threading.Semaphore(0)
    real = Approvals.authenticate
    hashed_on: list[int] = []

    def held(self, name, password):
        hashed_on.append(threading.get_ident())
        started.release()
        release.wait(30)
        return real(self, name, password)

    monkeypatch.setattr(Approvals, "authenticate", held)
    app = create_app([lab[0]], lab[1], sign_in=lab[2].policy())

    async def scenario() -> None:
        transport = httpx.ASGITransport(app=app, client=("10.0.3.1", 50000))
        loop_thread = threading.get_ident()
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
            token = re.search(r'name="csrf" value="([^"]+)"', (await client.get("/login")).text).group(1)
            answers: list[int] = []

            async def wrong_login() -> None:
                answer = await client.post("/login", data={"csrf": token, "name": "jdoe", "password": "guess"},
                                           headers=ORIGIN)
                answers.append(answer.status_code)

            async with anyio.create_task_group() as group:
                for _ in range(4):
                    group.start_soon(wrong_login)
                for _ in range(2):                      # both hashing threads are taken
                    assert await anyio.to_thread.run_sync(started.acquire, True, 30)
                with anyio.fail_after(20):             # a deadline, not a timing: served at all while they wait
                    for path in ("/static/dashboard.css", "/login", "/"):
                        assert (await client.get(path)).status_code == 200
                release.set()
            assert sorted(answers) == [401] * 4
            assert len(hashed_on) == 4 and loop_thread not in hashed_on

    anyio.run(scenario)
