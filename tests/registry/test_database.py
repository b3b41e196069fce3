"""The registry on SQLite and on a real PostgreSQL server: created on first use at the current schema,
recording each DUT's calibration once however often it is added, and answering by serial, part, date and
verdict."""

from __future__ import annotations

from datetime import datetime, timedelta

import pytest

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.registry.database import Registry, head_revision
from accelcal_rig.registry.entries import calibration_file_of, campaign_entries
from accelcal_rig.registry.figures import reference_figures


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
    assert row["bias_mg"] == pytest.approx(reference_figures(row["calibration"])["bias_mg"])
    # What is stored is the whole fit: it makes the calibration file again, equal to the one fitted.
    again = calibration_file_of(row).sensors[row["serial"]]
    assert again == load_calibration(calibration).sensors[row["serial"]]


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
    assert registry.current(serial) is None                   # awaiting approval: not valid yet
    approve(registry, added)                                  # (tests/registry/test_approvals.py: the rules)
    current = registry.current(serial)
    assert current is not None and current["calibrated_at"] == base["calibrated_at"]  # the newest approved
    registry.add([rehearsal])
    assert registry.current(serial)["calibrated_at"] == base["calibrated_at"]  # a dry run is no calibration
    assert registry.current(serial, simulated=True)["calibrated_at"] == rehearsal["calibrated_at"]
    registry.add([failed])
    # The quick procedure states no limits: NOT JUDGED, registered with no verdict (counted in no yield).
    assert [r["verdict"] for r in registry.calibrations(serial=serial)] == [None, "FAIL", None, None]
    assert registry.current(serial) is None  # the newest real one failed: the sensor is out of tolerance now
    assert [r["serial"] for r in registry.calibrations(part="adxl357")] == ["X-1"]
    assert len(registry.calibrations(since=base["calibrated_at"] - timedelta(days=1))) == 4
    assert len(registry.calibrations(verdict="FAIL")) == 1
    assert registry.parts() == ["adxl355", "adxl357"]
    assert len(registry.calibrations(limit=2)) == 2
    assert registry.current("NOBODY") is None
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


def test_readers_do_not_migrate_but_create_a_new_registry(registry_url: str) -> None:
    assert Registry.open(registry_url, upgrade=False).revision() == head_revision()  # new: created
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
