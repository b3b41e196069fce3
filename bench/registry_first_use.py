"""A registry's first use and a registry that does not answer, as processes, the way a lab meets them:

- **first use:** 20 `rig registry add` processes started at once on a registry that does not exist yet (a
  new SQLite file; with `--postgresql URL`, also a new database on that server), `--trials` times each.
  A trial passes when every process exits 0 and every calibration is there once (one migration, no
  "duplicate column", no row missing).
- **silent server:** a TCP listener that accepts connections and never answers, named as a PostgreSQL
  registry: `rig registry list` must fail in one line within the connect timeout (10 s, or the URL's own
  `connect_timeout`).

Usage:

    python bench/registry_first_use.py [--trials 20] [--writers 20] [--postgresql postgresql:///db?host=/var/run/postgresql] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import sqlite3
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

import sqlalchemy as sa
from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.registry.location import normalised

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")


def finished_campaign(folder: Path) -> Path:
    """A dry run of quick-6pos with its calibration beside it: what each writer records (4 DUTs)."""
    silence_campaign_log()
    campaign = folder / "quick.h5"
    run_campaign(prepare(REPO / "procedures" / "quick-6pos.yaml"), campaign, dry_run=True, seed=0, overwrite=False,
                 calibration=campaign.with_suffix(".calibration.yaml"))
    return campaign


def writers_at_once(url: str, campaign: Path, writers: int) -> tuple[list[str], float]:
    """`writers` processes of `rig registry add` on `url`, started together; (one line per failure, wall s)."""
    start = time.perf_counter()
    processes = [subprocess.Popen([RIG, "registry", "add", str(campaign), "--registry", url],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(writers)]
    failures = []
    for process in processes:
        _, err = process.communicate(timeout=600)
        if process.returncode != 0:
            failures.append(f"exit {process.returncode}: {err.strip().splitlines()[-1] if err.strip() else ''}")
    return failures, time.perf_counter() - start


def rows_per_serial(url: str) -> dict[str, int]:
    if url.startswith("sqlite:///"):
        with sqlite3.connect(url.removeprefix("sqlite:///")) as connection:
            return dict(connection.execute("SELECT serial, count(*) FROM calibrations GROUP BY serial").fetchall())
    engine = sa.create_engine(normalised(url), poolclass=sa.pool.NullPool)
    with engine.connect() as connection:
        found = dict(connection.execute(sa.text("SELECT serial, count(*) FROM calibrations GROUP BY serial")).all())
    engine.dispose()
    return {str(k): int(v) for k, v in found.items()}


def first_use(kind: str, new_url, campaign: Path, trials: int, writers: int) -> dict[str, object]:  # noqa: ANN001
    """`trials` trials of `writers` writers on a registry `new_url()` makes (and a cleanup it returns)."""
    passed, walls, seen = 0, [], []
    for trial in range(trials):
        url, cleanup = new_url(trial)
        try:
            failures, wall = writers_at_once(url, campaign, writers)
            rows = rows_per_serial(url)
        finally:
            cleanup()
        ok = not failures and len(rows) == 4 and set(rows.values()) == {1}
        passed += ok
        walls.append(wall)
        if not ok:
            seen.append({"trial": trial, "failures": failures, "rows": rows})
        print(f"{kind:10s} trial {trial:2d}: {'pass' if ok else 'FAIL'} in {wall:5.1f} s, rows per serial "
              f"{sorted(set(rows.values()))} {failures[:2]}", flush=True)
    return {"trials": trials, "writers": writers, "passed": passed, "wall_median_s": sorted(walls)[len(walls) // 2],
            "failed": seen}


def sqlite_registry(folder: Path):  # noqa: ANN201
    def new(trial: int) -> tuple[str, object]:
        path = folder / f"first-use-{trial}.sqlite"
        return normalised(str(path)), lambda: [p.unlink() for p in folder.glob(path.name + "*")]
    return new


def postgresql_registry(server: str):  # noqa: ANN201
    admin = sa.create_engine(normalised(server), isolation_level="AUTOCOMMIT", poolclass=sa.pool.NullPool)

    def new(trial: int) -> tuple[str, object]:
        name = f"first_use_{uuid.uuid4().hex[:10]}"
        with admin.connect() as connection:
            connection.execute(sa.text(f'CREATE DATABASE "{name}"'))
        url = sa.engine.make_url(normalised(server)).set(database=name).render_as_string(hide_password=False)

        def drop() -> None:
            with admin.connect() as connection:
                connection.execute(sa.text(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)'))
        return url, drop
    return new


def silent_server(connect_timeout_s: int | None) -> dict[str, object]:
    """`rig registry list` against a listener that accepts and never answers."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(16)
    held: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        listener.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(listener.accept()[0])
            except TimeoutError:
                continue

    threading.Thread(target=accept, daemon=True).start()
    port = listener.getsockname()[1]
    query = f"?connect_timeout={connect_timeout_s}" if connect_timeout_s else ""
    start = time.perf_counter()
    result = subprocess.run([RIG, "registry", "list", "--registry", f"postgresql://lab@127.0.0.1:{port}/registry{query}"],
                            capture_output=True, text=True, timeout=300)
    wall = time.perf_counter() - start
    stop.set()
    for connection in held:
        connection.close()
    listener.close()
    lines = result.stderr.strip().splitlines()
    print(f"silent server, connect_timeout {connect_timeout_s or 'default'}: exit {result.returncode} in {wall:.1f} s: "
          f"{lines[-1] if lines else ''} ({len(lines)} line(s))", flush=True)
    return {"exit": result.returncode, "wall_s": wall, "lines": len(lines), "message": lines[-1] if lines else ""}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--writers", type=int, default=20)
    parser.add_argument("--postgresql", help="a PostgreSQL server URL this may create databases on")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    figures: dict[str, object] = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        campaign = finished_campaign(folder)
        figures["sqlite"] = first_use("sqlite", sqlite_registry(folder), campaign, args.trials, args.writers)
        if args.postgresql:
            figures["postgresql"] = first_use("postgresql", postgresql_registry(args.postgresql), campaign,
                                              args.trials, args.writers)
    figures["silent_server_default"] = silent_server(None)
    figures["silent_server_2s"] = silent_server(2)
    if args.json:
        print(json.dumps(figures))
    ok = all(f["passed"] == f["trials"] for k, f in figures.items() if isinstance(f, dict) and "trials" in f)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
