"""Two rigs finishing at once: two processes open a registry nobody has created yet and each records 100
calibrations of its own and 50 that both hold, at the same moment — every one is there, once."""

from __future__ import annotations

import pickle
import select
import subprocess
import sys
import threading
from pathlib import Path

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.entries import campaign_entries
from tests.registry.conftest import synthetic_entries

WRITER = """
import pickle, sys, time
from pathlib import Path
from accelcal_rig.registry.database import Registry
url, entries_file, go = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
entries = pickle.loads(entries_file.read_bytes())
print("ready", flush=True)
deadline = time.monotonic() + 60
while not go.exists():
    assert time.monotonic() < deadline, "never told to go"
    time.sleep(0.001)
added, already = Registry.open(url).add(entries)
print(len(added), already)
"""


def test_two_writers_at_once_lose_nothing_and_duplicate_nothing(registry_url: str, quick_campaign, tmp_path: Path) -> None:
    campaign, calibration = quick_campaign
    template = campaign_entries(campaign, calibration)[0]
    shared = synthetic_entries(template, 50, prefix="BOTH")
    go = tmp_path / "go"
    writers = []
    for rig in ("A", "B"):
        entries_file = tmp_path / f"{rig}.pickle"
        entries_file.write_bytes(pickle.dumps([*synthetic_entries(template, 100, prefix=f"RIG{rig}"), *shared]))
        writers.append(subprocess.Popen([sys.executable, "-c", WRITER, registry_url, str(entries_file), str(go)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    for writer in writers:  # both started, and waiting for the word (within a deadline: a stuck one fails)
        assert writer.stdout is not None
        assert select.select([writer.stdout], [], [], 60)[0], "a writer never said it was ready"
        assert writer.stdout.readline().strip() == "ready"
    go.touch()
    results = [writer.communicate(timeout=120) for writer in writers]
    assert all(writer.returncode == 0 for writer in writers), [err for _, err in results]
    counts = [tuple(int(n) for n in out.split()) for out, _ in results]  # what each printed after "ready"
    assert sum(added for added, _ in counts) == 250 and sum(already for _, already in counts) == 50
    registry = Registry.open(registry_url)
    assert registry.count() == 250
    assert len({r["serial"] for r in registry.calibrations()}) == 250


def test_twenty_writers_on_a_registry_nobody_made_migrate_it_once(registry_url: str, quick_campaign) -> None:
    """Twenty recorders meet a new database at the same moment (threads, each its own connections): one
    migrates it, the others wait for the schema and record; no "duplicate column", no row lost. Three
    trials; bench/registry.py --first-use runs 20 trials of 20 processes."""
    campaign, calibration = quick_campaign
    template = campaign_entries(campaign, calibration)[0]
    for trial in range(3):
        url = registry_url if trial == 0 else _fresh(registry_url, trial)
        try:
            _twenty_at_once(url, template)
        finally:
            _drop(registry_url, url)


def _twenty_at_once(url: str, template: dict) -> None:
    """Twenty threads, released together, each opening `url` and recording two calibrations of its own."""
    start = threading.Barrier(20)
    failures: list[str] = []

    def record(k: int) -> None:
        start.wait(timeout=60)
        try:
            Registry.open(url).add(synthetic_entries(template, 2, prefix=f"W{k}"))
        except Exception as exc:  # noqa: BLE001 - every failure of any writer is what the test reports
            failures.append(f"{type(exc).__name__}: {exc}")

    writers = [threading.Thread(target=record, args=(k,)) for k in range(20)]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join(timeout=120)
    assert not failures, failures
    assert Registry.open(url).count() == 40


def _drop(fixture_url: str, url: str) -> None:
    """A PostgreSQL database this test made beside the fixture's (the fixture drops its own)."""
    if url == fixture_url or url.startswith("sqlite:///"):
        return
    import sqlalchemy as sa

    admin = sa.create_engine(fixture_url, isolation_level="AUTOCOMMIT", poolclass=sa.pool.NullPool)
    with admin.connect() as connection:
        connection.execute(sa.text(f'DROP DATABASE IF EXISTS "{sa.engine.make_url(url).database}" WITH (FORCE)'))
    admin.dispose()


def _fresh(url: str, trial: int) -> str:
    """Another new database beside the fixture's: an SQLite file, or a PostgreSQL database of its own."""
    if url.startswith("sqlite:///"):
        return url.replace(".sqlite", f"-{trial}.sqlite")
    import sqlalchemy as sa

    name = f"{sa.engine.make_url(url).database}_{trial}"
    admin = sa.create_engine(url, isolation_level="AUTOCOMMIT", poolclass=sa.pool.NullPool)
    with admin.connect() as connection:
        connection.execute(sa.text(f'CREATE DATABASE "{name}"'))
    admin.dispose()
    return sa.engine.make_url(url).set(database=name).render_as_string(hide_password=False)
