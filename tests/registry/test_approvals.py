"""Approval in the registry, on SQLite and PostgreSQL: the lab's users with argon2 passwords, an append-only
record of who decided what and when (the database refuses to change it), certificate revisions that stay
retrievable, and a serial's valid calibration only an approved real one."""

from __future__ import annotations

from datetime import timedelta

import pytest
import sqlalchemy as sa

from accelcal_rig.errors import ConfigError
from accelcal_rig.registry.approvals import Approvals, IssuedCertificate
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.entries import campaign_entries

PASSWORD = "correct horse battery"


def issued(revision: int, text: str = "") -> IssuedCertificate:
    return IssuedCertificate(revision, "ADX355-A001-TEST", f"<p>revision {revision} {text}</p>", b"%PDF-" + bytes([revision]))


@pytest.fixture
def book(registry_url: str) -> Approvals:
    approvals = Approvals(Registry.open(registry_url))
    approvals.add_user("jdoe", "J. Doe", "approver", PASSWORD)
    approvals.add_user("viewer", "V. Iewer", "viewer", PASSWORD)
    return approvals


def test_passwords_are_argon2_hashes_and_only_the_right_one_authenticates(book: Approvals) -> None:
    with book.registry.engine.connect() as connection:
        stored = connection.execute(sa.text("SELECT password_hash FROM users WHERE name = 'jdoe'")).scalar_one()
    assert stored.startswith("$argon2id$") and PASSWORD not in stored
    assert book.authenticate("jdoe", PASSWORD).full_name == "J. Doe"
    assert book.authenticate("jdoe", PASSWORD + "!") is None and book.authenticate("nobody", PASSWORD) is None
    book.set_disabled("jdoe", True)
    assert book.authenticate("jdoe", PASSWORD) is None
    with pytest.raises(ConfigError, match="at least 8 characters"):
        book.add_user("short", "S. Hort", "approver", "1234567")
    with pytest.raises(ConfigError, match="user jdoe exists already"):
        book.add_user("jdoe", "J. Doe", "approver", PASSWORD)
    book.add_user("proxied", "P. Roxied", "approver", None)         # the reverse proxy authenticates them
    assert book.authenticate("proxied", "") is None and book.user("proxied").may_approve


def test_decisions_are_recorded_append_only_and_every_revision_stays(book: Approvals, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    added, _ = book.registry.add(campaign_entries(campaign, calibration))
    lead = added[0]
    jdoe, viewer = book.user("jdoe"), book.user("viewer")
    assert book.decision(lead).state == "awaiting approval"
    with pytest.raises(ConfigError, match="may not approve"):
        book.record(lead, "approve", viewer, "test", certificate=issued(1))
    with pytest.raises(ConfigError, match="no certificate to reissue"):
        book.record(lead, "reissue", jdoe, "test", "customer's name corrected", issued(1))
    assert book.record(lead, "approve", jdoe, "test", certificate=issued(1)) == 1
    with pytest.raises(ConfigError, match="approved already"):
        book.record(lead, "approve", jdoe, "test", certificate=issued(2))
    with pytest.raises(ConfigError, match="needs a reason"):
        book.record(lead, "reissue", jdoe, "test", " ", issued(2))
    assert book.record(lead, "reissue", jdoe, "test", "customer's name corrected", issued(2, "corrected")) == 2
    decision = book.decision(lead)
    assert (decision.state, decision.revision, decision.by) == ("approved", 2, "J. Doe")
    assert [c["revision"] for c in book.certificates(lead)] == [1, 2]
    assert book.certificate(lead, 1)["html"] == "<p>revision 1 </p>"   # the old revision, as issued
    assert bytes(book.certificate(lead, 2)["pdf"]) == b"%PDF-\x02"
    book.record(lead, "reject", jdoe, "test", "the fixture was loose")
    assert book.decision(lead).state == "rejected"
    assert [(t["action"], t["revision"]) for t in book.trail(calibration_id=lead)] == [
        ("approve", 1), ("reissue", 2), ("reject", None)]
    # The database itself refuses to change or delete the record, whoever asks.
    sqlite = book.registry.engine.dialect.name == "sqlite"
    replace = ("REPLACE INTO approvals (id, calibration_id, action, user_name, full_name, authority, reason, at) "
               "SELECT id, calibration_id, 'approve', 'mallory', 'Mallory', 'x', '', at FROM approvals LIMIT 1" if sqlite
               else "INSERT INTO approvals SELECT * FROM approvals LIMIT 1 ON CONFLICT (id) DO UPDATE SET user_name = 'm'")
    for statement in ("UPDATE approvals SET user_name = 'mallory'", "DELETE FROM approvals",
                      "DELETE FROM certificate_revisions", "UPDATE certificate_revisions SET approver = 'mallory'",
                      replace):
        with pytest.raises(sa.exc.DBAPIError, match="append-only"), book.registry.engine.begin() as connection:
            connection.execute(sa.text(statement))
    # What was decided keeps its identity and fit; a decision names a calibration that exists.
    for statement in (f"UPDATE calibrations SET verdict = 'PASS' WHERE id = {lead}",
                      f"DELETE FROM calibrations WHERE id = {lead}"):
        with pytest.raises(sa.exc.DBAPIError, match="decided calibration cannot change"), \
                book.registry.engine.begin() as connection:
            connection.execute(sa.text(statement))
    with pytest.raises(sa.exc.IntegrityError), book.registry.engine.begin() as connection:
        connection.execute(sa.text("INSERT INTO approvals (calibration_id, action, user_name, full_name, authority, "
                                   "reason, at) VALUES (999999, 'approve', 'm', 'M', 'x', '', CURRENT_TIMESTAMP)"))
    assert len(book.trail()) == 3


def test_only_an_approved_real_calibration_is_valid(book: Approvals, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = book.registry
    base = campaign_entries(campaign, calibration)[0] | {"simulated": False}
    newer = base | {"fit_sha256": "1" * 64, "calibrated_at": base["calibrated_at"] + timedelta(days=30)}
    failed = base | {"fit_sha256": "2" * 64, "calibrated_at": base["calibrated_at"] + timedelta(days=60),
                     "verdict": "FAIL"}
    (first,), _ = registry.add([base])
    serial, jdoe = base["serial"], book.user("jdoe")
    assert registry.current(serial, channel="accel") is None                          # awaiting approval: not valid yet
    book.record(first, "approve", jdoe, "test", certificate=issued(1))
    assert registry.current(serial, channel="accel")["id"] == first
    (second,), _ = registry.add([newer])
    assert registry.current(serial, channel="accel")["id"] == first                   # the newer one awaits: the approved stays
    book.record(second, "reject", jdoe, "test", "wrong fixture")
    assert registry.current(serial, channel="accel")["id"] == first                   # rejected: never valid
    (third,), _ = registry.add([failed])
    assert registry.current(serial, channel="accel") is None                          # out of tolerance now
    assert "out of tolerance" in registry.why_not_valid(serial, "accel")
    book.record(third, "reject", jdoe, "test", "the chamber's sensor was out of calibration")
    assert registry.current(serial, channel="accel")["id"] == first                   # a rejected measurement says nothing
