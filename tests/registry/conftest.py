"""The registry's backends for the tests: an SQLite file, and a real PostgreSQL server — the one CI starts
(ACCELCAL_TEST_POSTGRESQL, a URL), else a private one started from Debian's postgresql binaries for the
session. Each test gets a database of its own."""

from __future__ import annotations

import glob
import os
import shutil
import socket
import subprocess
import tempfile
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
import sqlalchemy as sa

from accelcal_rig.registry.location import normalised


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture(scope="session")
def postgresql_server() -> Iterator[str]:
    """A URL of a PostgreSQL server this session may create databases on."""
    configured = os.environ.get("ACCELCAL_TEST_POSTGRESQL")
    if configured:
        yield normalised(configured)
        return
    binaries = sorted(glob.glob("/usr/lib/postgresql/*/bin"))
    if not binaries:
        raise RuntimeError("the registry's PostgreSQL tests need a server: install Debian's postgresql package, "
                           "or set ACCELCAL_TEST_POSTGRESQL to a URL of one")
    bin_dir = Path(binaries[-1])
    data = Path(tempfile.mkdtemp(prefix="accelcal-postgresql-"))  # outside pytest's private tree: postgres reads it
    as_postgres: list[str] = []
    if os.geteuid() == 0:  # initdb will not run as root: the postgres user runs the private server
        shutil.chown(data, "postgres")
        as_postgres = ["runuser", "-u", "postgres", "--"]
    port = _free_port()
    subprocess.run([*as_postgres, str(bin_dir / "initdb"), "-D", str(data / "db"), "-A", "trust", "-U", "accelcal"],
                   check=True, capture_output=True)
    subprocess.run([*as_postgres, str(bin_dir / "pg_ctl"), "-D", str(data / "db"), "-w", "-l", str(data / "log"),
                    "-o", f"-k {data} -p {port} -c listen_addresses=''", "start"], check=True, capture_output=True)
    try:
        yield f"postgresql+psycopg://accelcal@/postgres?host={data}&port={port}"
    finally:
        subprocess.run([*as_postgres, str(bin_dir / "pg_ctl"), "-D", str(data / "db"), "-m", "fast", "stop"],
                       capture_output=True)
        shutil.rmtree(data, ignore_errors=True)


@pytest.fixture
def postgresql_url(postgresql_server: str) -> Iterator[str]:
    """A fresh, empty database on the server, dropped after the test."""
    name = f"registry_{uuid.uuid4().hex[:12]}"
    admin = sa.create_engine(postgresql_server, isolation_level="AUTOCOMMIT", poolclass=sa.pool.NullPool)
    with admin.connect() as connection:
        connection.execute(sa.text(f'CREATE DATABASE "{name}"'))
    url = sa.engine.make_url(postgresql_server).set(database=name).render_as_string(hide_password=False)
    yield url
    with admin.connect() as connection:
        connection.execute(sa.text(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)'))
    admin.dispose()


@pytest.fixture(params=["sqlite", "postgresql"])
def registry_url(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    """Each registry test runs on both backends."""
    if request.param == "sqlite":
        return normalised(str(tmp_path / "registry.sqlite"))
    return request.getfixturevalue("postgresql_url")


@pytest.fixture(scope="session")
def quick_campaign(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """One finished dry run of quick-6pos (4 DUTs) and its calibration: (campaign, calibration)."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare
    from tests.conftest import REPO

    output = tmp_path_factory.mktemp("quick") / "quick.h5"
    calibration = output.with_suffix(".calibration.yaml")
    run_campaign(prepare(REPO / "procedures" / "quick-6pos.yaml"), output, dry_run=True, seed=0, overwrite=False,
                 calibration=calibration)
    return output, calibration


def synthetic_entries(template: dict, count: int, prefix: str = "SYN", start_day: int = 0) -> list[dict]:
    """`count` distinct calibrations made from one real entry: their own serials, fits and days."""
    from datetime import timedelta

    entries = []
    for k in range(count):
        entry = dict(template)
        entry.update(serial=f"{prefix}-{k:06d}", fit_sha256=uuid.uuid5(uuid.NAMESPACE_OID, f"{prefix}{k}").hex * 2,
                     calibrated_at=template["calibrated_at"] + timedelta(days=start_day + k))
        entries.append(entry)
    return entries
