"""Sign-ins in the registry (migration 0009): a 0008 registry's users upgrade with their passwords and no
lockout; failed logins lock an account after ACCOUNT_FAILURES in a row, `enable` lifts it and the record says so;
a new password, another role and disabling raise the user's session generation, each recorded; the command line
is limited like the dashboard and says who is locked out; `rig registry audit --sign-ins` lists the record."""

from __future__ import annotations

import io
import json
from datetime import datetime, timedelta
from pathlib import Path

import pytest
import sqlalchemy as sa

from accelcal_rig.cli import main
from accelcal_rig.registry.approvals import Approvals
from accelcal_rig.registry.database import Registry, RegistryTimeouts, _engine, head_revision
from accelcal_rig.registry.location import normalised
from accelcal_rig.registry.sign_ins import ACCOUNT_FAILURES, LOCKOUT_S, SignIns

PASSWORD = "approver's secret"
NOW = datetime(2026, 12, 7, 9, 0, 0)


@pytest.mark.parametrize("registry_url", ["sqlite", "postgresql"], indirect=True)
def test_a_0008_registry_upgrades_with_its_users_as_they_were(registry_url: str) -> None:
    old = Registry(_engine(registry_url, create=True, read_only=False, timeouts=RegistryTimeouts()), registry_url)
    old.upgrade("0008")
    hashed = "$argon2id$v=19$m=65536,t=3,p=4$c29tZXNhbHQ$RdescudvJCsgt3ub+b+dWRWJTmaaJObG"
    with old.engine.begin() as connection:
        connection.execute(sa.text("INSERT INTO users (name, full_name, role, password_hash, disabled, created_at) "
                                   "VALUES ('jdoe', 'Jane Doe', 'approver', :h, false, :at)"), {"h": hashed, "at": NOW})
    upgraded = Registry.open(registry_url)
    assert upgraded.revision() == head_revision()
    (user,) = Approvals(upgraded).users()
    assert (user.name, user.role, user.disabled, user.generation) == ("jdoe", "approver", False, 0)
    assert SignIns(upgraded).locked_for_s("jdoe", NOW) == 0 and SignIns(upgraded).record() == []
    with upgraded.engine.connect() as connection:
        assert connection.execute(sa.text("SELECT password_hash FROM users")).scalar() == hashed


@pytest.mark.parametrize("registry_url", ["sqlite", "postgresql"], indirect=True)
def test_failed_logins_lock_the_account_and_enable_lifts_it(registry_url: str) -> None:
    registry = Registry.open(registry_url)
    book, sign_ins = Approvals(registry), SignIns(registry)
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    locks = [sign_ins.failed("jdoe", "10.0.0.1", NOW) for _ in range(ACCOUNT_FAILURES)]
    assert locks == [0.0] * (ACCOUNT_FAILURES - 1) + [float(LOCKOUT_S)]
    assert sign_ins.locked_for_s("jdoe", NOW + timedelta(seconds=60)) == LOCKOUT_S - 60
    assert sign_ins.locked_for_s("jdoe", NOW + timedelta(seconds=LOCKOUT_S)) == 0        # lifted by time
    assert sign_ins.failed("nobody", "10.0.0.1", NOW) == 0                             # recorded, no account
    book.set_disabled("jdoe", False)                                                  # rig registry user enable
    assert sign_ins.locked_for_s("jdoe", NOW) == 0
    events = [(e["user_name"], e["event"]) for e in sign_ins.record()]
    assert events == ([("jdoe", "login failed")] * ACCOUNT_FAILURES + [("jdoe", "locked"), ("nobody", "login failed")]
                      + [("jdoe", "unlocked")])


@pytest.mark.parametrize("registry_url", ["sqlite", "postgresql"], indirect=True)
def test_a_change_to_a_user_raises_their_generation_and_is_recorded(registry_url: str) -> None:
    registry = Registry.open(registry_url)
    book, sign_ins = Approvals(registry), SignIns(registry)
    book.add_user("jdoe", "Jane Doe", "approver", PASSWORD)
    generations = [book.user("jdoe").generation]
    for change in (lambda: book.set_password("jdoe", "another secret"), lambda: book.set_role("jdoe", "viewer"),
                   lambda: book.set_disabled("jdoe", True), lambda: sign_ins.end_sessions("jdoe", "10.0.0.1", NOW,
                                                                                           "logout")):
        change()
        generations.append(book.user("jdoe").generation)
    assert generations == [0, 1, 2, 3, 4]
    assert [(e["event"], e["detail"]) for e in sign_ins.record("jdoe")] == [
        ("sessions ended", "password changed"), ("sessions ended", "role changed to viewer"),
        ("sessions ended", "disabled"), ("logout", "")]
    assert book.authenticate("jdoe", "another secret") is None                          # disabled


def rig(monkeypatch: pytest.MonkeyPatch, *args: str, stdin: str = "") -> int:
    monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
    return main(list(args))


def test_the_command_line_is_limited_alike_and_lists_the_record(tmp_path: Path, monkeypatch, capsys) -> None:
    registry = normalised(str(tmp_path / "registry.sqlite"))
    assert rig(monkeypatch, "registry", "user", "add", "jdoe", "--full-name", "Jane Doe", "--role", "approver",
               "--password-stdin", "--registry", registry, stdin=PASSWORD + "\n") == 0
    for _ in range(ACCOUNT_FAILURES):
        assert rig(monkeypatch, "registry", "user", "role", "jdoe", "--role", "viewer", "--by", "jdoe",
                   "--password-stdin", "--registry", registry, stdin="guess\n") == 2
    capsys.readouterr()
    assert rig(monkeypatch, "registry", "user", "role", "jdoe", "--role", "viewer", "--by", "jdoe",
               "--password-stdin", "--registry", registry, stdin=PASSWORD + "\n") == 2
    assert "user jdoe: locked out after too many failed logins" in capsys.readouterr().err
    Approvals(Registry.open(registry)).set_disabled("jdoe", False)
    assert rig(monkeypatch, "registry", "user", "role", "jdoe", "--role", "viewer", "--by", "jdoe",
               "--password-stdin", "--registry", registry, stdin=PASSWORD + "\n") == 0
    assert "now viewer; every session of theirs has ended" in capsys.readouterr().out
    assert rig(monkeypatch, "registry", "audit", "--sign-ins", "jdoe", "--json", "--registry", registry) == 0
    record = json.loads(capsys.readouterr().out)
    assert [e["event"] for e in record] == (["login failed"] * ACCOUNT_FAILURES
                                            + ["locked", "unlocked", "login", "sessions ended"])
    assert {e["client"] for e in record} == {"command line"}
    assert rig(monkeypatch, "registry", "audit", "--sign-ins", "--registry", registry) == 0
    assert "jdoe                 locked          from command line: 5 failed logins in a row" in capsys.readouterr().out
