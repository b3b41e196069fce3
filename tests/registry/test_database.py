"""The registry on SQLite and on a real PostgreSQL server: created on first use at the current schema,
recording each DUT's calibration once however often it is added, and answering by serial, part, date and
verdict."""

from __future__ import annotations

import socket
import sqlite3
import subprocess
import threading
from datetime import datetime, timedelta
from pathlib import Path

import pytest

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.entries import calibration_file_of, campaign_entries
from accelcal_rig.registry.migrations.frozen_figures import reference_figures


def test_first_use_creates_the_schema_at_its_current_version(registry_url: str) -> None:
    registry = Registry.open(registry_url)
    assert registry.revision() == head_revision()
    assert registry.count() == 0
    assert Registry.open(registry_url).revision() == head_revision()  # opening again changes nothing


def test_a_campaign_is_recorded_once_per_dut_however_often_it_is_added(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry.open(registry_url)
    entries = campaign_entries(campaign, calibration)
    added, already = registry.add(entries)
    assert len(added) == 4 and already == 0
    assert registry.add(campaign_entries(campaign, calibration)) == ([], 4)
    rows = registry.calibrations()
    assert sorted(r["serial"] for r in rows) == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]
    assert "calibration" not in rows[0]  # listing leaves the stored fits out
    row = registry.calibration(added[0])
    assert row["part"] == "adxl355" and row["simulated"] and row["procedure"] == "quick-6pos"
    assert row["source_path"] == str(campaign.resolve()) and len(row["source_sha256"]) == 64
    assert row["figures"]["bias"]["value"] == pytest.approx(reference_figures(row["calibration"])["bias_mg"])
    # What is stored is the whole fit: it makes the calibration file again, equal to the one fitted.
    again = calibration_file_of([row]).of_quantity("acceleration")[row["serial"]]
    assert again == load_calibration(calibration).of_quantity("acceleration")[row["serial"]]


def approve(registry: Registry, ids: list[int]) -> None:
    """Each calibration approved by a lab's approver (its certificate a placeholder)."""
    from accelcal_rig.registry.approvals import Approvals, IssuedCertificate

    book = Approvals(registry)
    if book.user("approver") is None:
        book.add_user("approver", "A. Prover", "approver", "long enough password")
    for row_id in ids:
        book.record(row_id, "approve", book.user("approver"), "test",
                    certificate=IssuedCertificate(book.next_revision(row_id), "N", "<p></p>", None))


def test_filters_and_the_valid_calibration(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry.open(registry_url)
    base = campaign_entries(campaign, calibration)[0] | {"simulated": False}  # as a real rig's
    older = base | {"fit_sha256": "1" * 64, "calibrated_at": base["calibrated_at"] - timedelta(days=400)}
    failed = base | {"fit_sha256": "2" * 64, "calibrated_at": base["calibrated_at"] + timedelta(days=1),
                     "verdict": "FAIL"}
    rehearsal = base | {"fit_sha256": "4" * 64, "calibrated_at": base["calibrated_at"] + timedelta(days=2),
                        "simulated": True}
    other_part = base | {"fit_sha256": "3" * 64, "serial": "X-1", "part": "adxl357"}
    added, _ = registry.add([older, base, other_part])
    serial = base["serial"]
    assert registry.current(serial, channel="accel") is None                   # awaiting approval: not valid yet
    approve(registry, added)                                  # (tests/registry/test_approvals.py: the rules)
    current = registry.current(serial, channel="accel")
    assert current is not None and current["calibrated_at"] == base["calibrated_at"]  # the newest approved
    registry.add([rehearsal])
    assert registry.current(serial, channel="accel")["calibrated_at"] == base["calibrated_at"]  # a dry run is no calibration
    assert registry.current(serial, simulated=True, channel="accel")["calibrated_at"] == rehearsal["calibrated_at"]
    registry.add([failed])
    # The quick procedure states no limits: NOT JUDGED, registered with no verdict (counted in no yield).
    assert [r["verdict"] for r in registry.calibrations(serial=serial)] == [None, "FAIL", None, None]
    assert registry.current(serial, channel="accel") is None  # the newest real one failed: the sensor is out of tolerance now
    assert [r["serial"] for r in registry.calibrations(part="adxl357")] == ["X-1"]
    assert len(registry.calibrations(since=base["calibrated_at"] - timedelta(days=1))) == 4
    assert len(registry.calibrations(verdict="FAIL")) == 1
    assert registry.parts() == ["adxl355", "adxl357"]
    assert len(registry.calibrations(limit=2)) == 2
    assert registry.current("NOBODY", channel="accel") is None
    with pytest.raises(ConfigError, match="no calibration 999"):
        registry.calibration(999)


def test_a_registry_that_cannot_be_opened_is_one_line_naming_it(tmp_path) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    with pytest.raises(ConfigError, match=r"registry sqlite:///.*/file/registry.sqlite: cannot create its folder"):
        Registry.open(f"sqlite:///{blocked}/registry.sqlite")
    with pytest.raises(ConfigError, match=r"registry postgresql\+psycopg://lab@127.0.0.1:9/x: cannot open"):
        Registry.open("postgresql+psycopg://lab:secret@127.0.0.1:9/x")


def test_a_calibration_of_other_measurements_is_refused(tmp_path, quick_campaign) -> None:
    import shutil

    import yaml

    campaign, calibration = quick_campaign
    other = tmp_path / "other.calibration.yaml"
    data = yaml.safe_load(calibration.read_text())
    data["source"]["measurements_sha256"] = "0" * 64
    other.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError, match="fitted to other measurements than .* holds"):
        campaign_entries(campaign, other)
    shutil.copy(campaign, tmp_path / "copy.h5")
    assert campaign_entries(tmp_path / "copy.h5", calibration)  # the same measurements, another file: fine


def test_a_refit_of_an_old_campaign_is_not_a_newer_calibration(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    entry = campaign_entries(campaign, calibration)[0]
    assert entry["fitted_at"] >= entry["calibrated_at"]  # measured at the campaign's end, fitted after


def test_a_schema_newer_than_this_software_is_one_line(registry_url: str) -> None:
    import sqlalchemy as sa

    registry = Registry.open(registry_url)
    with registry.engine.begin() as connection:
        connection.execute(sa.text("UPDATE alembic_version SET version_num = '0099'"))
    with pytest.raises(ConfigError, match=f"schema 0099 is newer than this software's {head_revision()}: upgrade "
                                          "accelcal-rig"):
        Registry.open(registry_url)


def test_readers_do_not_migrate_and_create_nothing(registry_url: str) -> None:
    if registry_url.startswith("sqlite:///"):
        with pytest.raises(ConfigError, match="does not exist"):
            Registry.open(registry_url, upgrade=False, create=False, read_only=True)
        assert not Path(registry_url.removeprefix("sqlite:///")).exists()
    else:  # a database with nothing in it: empty, and left so
        with pytest.raises(ConfigError, match=r"empty \(nothing recorded in it yet\)"):
            Registry.open(registry_url, upgrade=False, create=False, read_only=True)
    assert Registry.open(registry_url, upgrade=False).revision() == head_revision()  # a recorder creates it
    older = Registry.open(registry_url)
    older.engine.dispose()
    import sqlalchemy as sa

    with Registry.open(registry_url).engine.begin() as connection:
        connection.execute(sa.text("UPDATE alembic_version SET version_num = '0001'"))
    with pytest.raises(ConfigError, match=f"schema 0001 is older than this software's {head_revision()}: a "
                                          "recording command"):
        Registry.open(registry_url, upgrade=False)


def test_times_are_stored_as_utc(registry_url: str, quick_campaign) -> None:
    campaign, calibration = quick_campaign
    registry = Registry.open(registry_url)
    entry = campaign_entries(campaign, calibration)[0]
    registry.add([entry])
    stored = registry.calibrations()[0]
    assert stored["calibrated_at"].tzinfo is None and stored["calibrated_at"] == entry["calibrated_at"]
    from accelcal_rig.registry.entries import _utc

    assert _utc("2026-06-01T14:00:00+02:00") == datetime(2026, 6, 1, 12, 0, 0)  # another zone, as UTC
    assert abs(stored["registered_at"] - datetime.utcnow()) < timedelta(minutes=5)


def damaged(registry_url: str, quick_campaign, damage: str) -> None:
    """A registry with a calibration in it, then changed by hand as `damage` says."""
    import sqlalchemy as sa

    campaign, calibration = quick_campaign
    registry = Registry.open(registry_url)
    registry.add(campaign_entries(campaign, calibration))
    statement = {"a table dropped": "DROP TABLE certificate_revisions",
                 "a column dropped": "ALTER TABLE users DROP COLUMN full_name",
                 "a date that is not a date": "UPDATE calibrations SET calibrated_at = 'last tuesday'"}[damage]
    with registry.engine.begin() as connection:
        connection.execute(sa.text(statement))
    registry.engine.dispose()


@pytest.mark.parametrize(("damage", "message"), [
    ("a table dropped", "table certificate_revisions is missing: the database was damaged or changed by hand"),
    ("a column dropped", "table users lacks column full_name: the database was damaged or changed by hand"),
])
def test_a_registry_changed_by_hand_is_refused_when_opened(damage: str, message: str, registry_url: str,
                                                          quick_campaign) -> None:
    damaged(registry_url, quick_campaign, damage)
    for reader in (True, False):
        with pytest.raises(ConfigError, match=message):
            Registry.open(registry_url, upgrade=not reader, create=not reader, read_only=reader)


def test_a_row_that_cannot_be_read_is_one_line_naming_the_registry(tmp_path: Path, quick_campaign) -> None:
    url = f"sqlite:///{tmp_path / 'registry.sqlite'}"  # SQLite keeps any text in a date column; PostgreSQL would not
    damaged(url, quick_campaign, "a date that is not a date")
    registry = Registry.open(url, upgrade=False, create=False, read_only=True)
    with pytest.raises(ConfigError, match=r"cannot be read \(.*\): the database was damaged or changed by hand"):
        registry.calibrations()


def test_someone_elses_database_is_never_migrated_into(tmp_path: Path) -> None:
    foreign = tmp_path / "inventory.sqlite"
    with sqlite3.connect(foreign) as connection:
        connection.execute("CREATE TABLE parts (id INTEGER PRIMARY KEY, name TEXT)")
    before = foreign.read_bytes()
    for reader in (True, False):
        with pytest.raises(ConfigError, match=r"not an accelcal-rig registry \(it holds tables parts and no schema "
                                              r"revision\)"):
            Registry.open(f"sqlite:///{foreign}", upgrade=not reader, create=not reader, read_only=reader)
    assert foreign.read_bytes() == before
    not_a_database = tmp_path / "notes.sqlite"
    not_a_database.write_text("minutes of the lab meeting\n" * 100)
    with pytest.raises(ConfigError, match=r"registry sqlite:///.*notes.sqlite: .*file is not a database"):
        Registry.open(f"sqlite:///{not_a_database}", upgrade=False, create=False, read_only=True)


def test_a_registry_on_a_read_only_mount_is_read(tmp_path: Path, quick_campaign) -> None:
    """Mounted read-only (root: a tmpfs remounted ro), where SQLite cannot make its WAL side files."""
    mount = tmp_path / "mnt"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=8m", "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("needs to mount a tmpfs (root)")
    try:
        url = f"sqlite:///{mount / 'registry.sqlite'}"
        campaign, calibration = quick_campaign
        Registry.open(url).add(campaign_entries(campaign, calibration))
        subprocess.run(["mount", "-o", "remount,ro", str(mount)], check=True)
        registry = Registry.open(url, upgrade=False, create=False, read_only=True)
        assert registry.count() == 4 and len(registry.calibrations()) == 4
        with pytest.raises(ConfigError):  # a recorder cannot: one line, not a crash
            Registry.open(url).add(campaign_entries(campaign, calibration))
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)


def test_a_server_that_accepts_and_never_answers_is_one_line_within_the_connect_timeout() -> None:
    """The URL's own connect_timeout (1 s here; 10 s when it gives none): a deadline, not a wait of minutes."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(4)
    held: list[socket.socket] = []
    threading.Thread(target=lambda: held.append(listener.accept()[0]), daemon=True).start()
    port = listener.getsockname()[1]
    try:
        with pytest.raises(ConfigError, match=rf"registry postgresql\+psycopg://lab@127.0.0.1:{port}/r\?connect_timeout=1: "
                                              "cannot open: .*timeout"):
            Registry.open(f"postgresql://lab@127.0.0.1:{port}/r?connect_timeout=1".replace(
                "postgresql://", "postgresql+psycopg://"), upgrade=False, create=False, read_only=True)
    finally:
        listener.close()
        for connection in held:
            connection.close()


def test_a_registry_on_a_full_disk_is_still_read(tmp_path: Path, quick_campaign) -> None:
    """A full disk (root: a small tmpfs filled up) where SQLite cannot make its shared-memory file to read: read
    as immutable (its write-ahead log is empty: nothing to miss), by the command line and the dashboard alike."""
    from accelcal_rig.web.registry_gate import RegistryGate

    mount = tmp_path / "mnt"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("needs to mount a tmpfs (root)")
    try:
        url = f"sqlite:///{mount / 'registry.sqlite'}"
        campaign, calibration = quick_campaign
        Registry.open(url).add(campaign_entries(campaign, calibration))
        with open(mount / "filler", "wb") as filler:          # the disk full
            try:
                while True:
                    filler.write(b"\0" * 65536)
                    filler.flush()
            except OSError:
                pass
        assert Registry.open(url, upgrade=False, create=False, read_only=True).count() == 4
        gate = RegistryGate(url)
        assert gate.get().count() == 4 and gate.read_only       # the dashboard shows it; logins are refused
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)
