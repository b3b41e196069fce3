"""What publishing live status costs and how the lab's dashboard reads a full registry:

- **publish cost:** the same dry run (`--procedure`, default the paper campaign) with and without
  publishing (`rig run … --registry FILE` against `… --no-publish`), alternated `--runs` times each in the
  same hour; medians of the wall time and their ratio, and the writes each run made.
- **dashboard:** a registry (SQLite, or `--postgresql URL`: a fresh database made on that server) holding
  `--rigs` rigs × `--campaigns` campaigns each (every one with 200 events and 840 temperature points, one
  running per rig), then the front page, /api/rigs and a published campaign's page asked `--requests` times
  each through the app: median and slowest time per page.

Usage:

    python bench/live_status.py [--runs 3] [--procedure procedures/paper-24pos-thermal.yaml]
        [--rigs 20] [--campaigns 50] [--requests 20] [--postgresql URL] [--json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
import uuid
from datetime import UTC, datetime, timedelta
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")


def publish_cost(procedure: Path, runs: int) -> dict:
    walls: dict[str, list[float]] = {"publishing": [], "not publishing": []}
    with tempfile.TemporaryDirectory() as folder:
        registry = Path(folder) / "lab.sqlite"
        for k in range(runs):
            for mode in ("publishing", "not publishing"):
                started = time.perf_counter()
                subprocess.run([RIG, "run", str(procedure), "--dry-run", "-o", str(Path(folder) / "c.h5"), "--overwrite",
                                "-q", "--no-pdf", "--registry", str(registry), "--seed", str(k),
                                *([] if mode == "publishing" else ["--no-publish"])],
                               check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                walls[mode].append(time.perf_counter() - started)
        import sqlite3

        with sqlite3.connect(registry) as db:
            events, points = (db.execute(f"SELECT count(*) FROM {t}").fetchone()[0]
                              for t in ("live_events", "live_temperatures"))
    with_s, without_s = statistics.median(walls["publishing"]), statistics.median(walls["not publishing"])
    return {"procedure": procedure.name, "runs": runs, "with_s": round(with_s, 2), "without_s": round(without_s, 2),
            "ratio": round(with_s / without_s, 3), "events_last_run": events, "temperature_points_last_run": points}


def dashboard(url: str, rigs: int, campaigns: int, requests: int) -> dict:
    from starlette.testclient import TestClient

    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.live import LiveBoard, LiveEvent
    from accelcal_rig.web.app import create_app

    board = LiveBoard(Registry.open(url))
    started = datetime.now(UTC).replace(tzinfo=None)
    keys = []
    for r in range(rigs):
        for c in range(campaigns):
            key = uuid.uuid4().hex
            keys.append(key)
            running = c == campaigns - 1
            row = {"rig": f"rig-{r:02d}", "host": f"bench-{r:02d}", "campaign": f"/data/rig-{r:02d}/c{c:03d}.h5",
                   "procedure": "paper-24pos-thermal", "dry_run": False, "pid": 1000 + c,
                   "state": "running" if running else "done", "phase": "poses", "setpoint_c": 25.0,
                   "setpoint_number": 7, "setpoints_total": 14, "poses_done": 200, "poses_total": 432,
                   "chamber_c": 25.0, "dut_c": [25.1] * 4, "remaining_s": 3600.0, "clock_s": 30000.0,
                   "line": "T25 (7/14) poses", "warnings": 3, "errors": 0,
                   "verdicts": {} if running else {f"SN{r}{c}{d}": {"verdict": "PASS", "reasons": ["ok"]} for d in range(4)},
                   "findings": [], "abort_reason": "", "started_at": started - timedelta(days=campaigns - c)}
            board.begin(key, row, fresh=True)
            board.publish(key, row, [LiveEvent(60.0 * e, started, "info", "pose", f"pose {e} stored") for e in range(200)],
                          [(60.0 * p, 25.0, 25.1) for p in range(840)])
    client = TestClient(create_app([Path(tempfile.mkdtemp())], url), base_url="http://127.0.0.1")
    pages = {"/": "front page", "/api/rigs": "/api/rigs", f"/live/{keys[-1]}": "a published campaign"}
    timings = {}
    for address, name in pages.items():
        times = []
        for _ in range(requests):
            begun = time.perf_counter()
            response = client.get(address)
            times.append(time.perf_counter() - begun)
            assert response.status_code == 200, (address, response.status_code)
        timings[name] = {"median_ms": round(1000 * statistics.median(times), 1), "max_ms": round(1000 * max(times), 1)}
    return {"backend": board.engine.dialect.name, "rigs": rigs, "campaigns_per_rig": campaigns, "pages": timings}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--procedure", type=Path, default=REPO / "procedures" / "paper-24pos-thermal.yaml")
    parser.add_argument("--rigs", type=int, default=20)
    parser.add_argument("--campaigns", type=int, default=50)
    parser.add_argument("--requests", type=int, default=20)
    parser.add_argument("--postgresql", metavar="URL", help="measure the dashboard on a new database of this server")
    parser.add_argument("--skip-publish", action="store_true", help="only the dashboard")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    result: dict = {}
    if not args.skip_publish:
        result["publish"] = publish_cost(args.procedure, args.runs)
    if args.postgresql:
        import sqlalchemy as sa

        from accelcal_rig.registry.location import normalised

        name = f"live_bench_{uuid.uuid4().hex[:8]}"
        admin = sa.create_engine(normalised(args.postgresql), isolation_level="AUTOCOMMIT")
        with admin.connect() as connection:
            connection.execute(sa.text(f'CREATE DATABASE "{name}"'))
        try:
            url = sa.engine.make_url(normalised(args.postgresql)).set(database=name).render_as_string(hide_password=False)
            result["dashboard"] = dashboard(url, args.rigs, args.campaigns, args.requests)
        finally:
            with admin.connect() as connection:
                connection.execute(sa.text(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)'))
    else:
        with tempfile.TemporaryDirectory() as folder:
            result["dashboard"] = dashboard(f"sqlite:///{folder}/lab.sqlite", args.rigs, args.campaigns, args.requests)
    print(json.dumps(result, indent=None if args.json else 2))


if __name__ == "__main__":
    main()
