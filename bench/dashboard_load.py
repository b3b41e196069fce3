"""The dashboard under load, as a lab meets it: `rig serve` started as a user starts it, then at once — open
pages polling the rigs fragment and the campaigns list, event-stream clients, and a flood of wrong logins —
while the front page, a published campaign's live page and a static file are fetched over and over on the wall
clock. Each with an SQLite registry, a PostgreSQL one (a private server from Debian's postgresql binaries, or
`--postgresql URL`) and a PostgreSQL registry that accepts connections and never answers. Reported per
registry: p50 and p99 latency of each of the three (from 1 s in: the first answers of a server just started
are not the load's), the slowest with when it came, their statuses, and the server's resident memory (its
peak and at the end). Goal: p99 of `/` ≤ 1 s under the login flood and with the silent registry.

Usage:

    python bench/dashboard_load.py [--pages 40] [--streams 50] [--flood 40] [--seconds 20] [--postgresql URL] [--json]
"""

from __future__ import annotations

import argparse
import asyncio
import glob
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any

import httpx
import sqlalchemy as sa
from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.registry.approvals import Approvals
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")
PASSWORD = "approver's secret"
#: The measurements begin this long after the load does.
WARM_UP_S = 1.0


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class SilentServer:
    """Accepts every connection and answers nothing."""

    def __init__(self) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.held: list[socket.socket] = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                self.held.append(self.listener.accept()[0])
            except OSError:
                return

    def close(self) -> None:
        self.listener.close()
        for connection in self.held:
            connection.close()


class PrivatePostgreSQL:
    """A throw-away PostgreSQL server from Debian's binaries (as the test suite starts one)."""

    def __init__(self) -> None:
        binaries = sorted(glob.glob("/usr/lib/postgresql/*/bin"))
        if not binaries:
            raise SystemExit("no PostgreSQL: install Debian's postgresql package, or give --postgresql URL")
        self.bin_dir = Path(binaries[-1])
        self.data = Path(tempfile.mkdtemp(prefix="accelcal-bench-postgresql-"))
        self.as_postgres: list[str] = []
        if os.geteuid() == 0:
            shutil.chown(self.data, "postgres")
            self.as_postgres = ["runuser", "-u", "postgres", "--"]
        port = free_port()
        subprocess.run([*self.as_postgres, str(self.bin_dir / "initdb"), "-D", str(self.data / "db"), "-A", "trust",
                        "-U", "accelcal"], check=True, capture_output=True)
        subprocess.run([*self.as_postgres, str(self.bin_dir / "pg_ctl"), "-D", str(self.data / "db"), "-w", "-l",
                        str(self.data / "log"), "-o", f"-k {self.data} -p {port} -c listen_addresses=''", "start"],
                       check=True, capture_output=True)
        self.url = f"postgresql+psycopg://accelcal@/postgres?host={self.data}&port={port}"

    def stop(self) -> None:
        subprocess.run([*self.as_postgres, str(self.bin_dir / "pg_ctl"), "-D", str(self.data / "db"), "-m", "fast",
                        "stop"], capture_output=True)
        shutil.rmtree(self.data, ignore_errors=True)


def fresh_database(server_url: str) -> str:
    name = f"bench_{uuid.uuid4().hex[:12]}"
    admin = sa.create_engine(server_url, isolation_level="AUTOCOMMIT", poolclass=sa.pool.NullPool)
    with admin.connect() as connection:
        connection.execute(sa.text(f'CREATE DATABASE "{name}"'))
    admin.dispose()
    return sa.engine.make_url(server_url).set(database=name).render_as_string(hide_password=False)


def filled(url: str, folder: Path) -> None:
    """A quick dry run recorded and published in the registry at `url` (as `rig run` does), and an approver."""
    subprocess.run([RIG, "run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-q", "--no-pdf",
                    "-o", str(folder / f"quick-{uuid.uuid4().hex[:6]}.h5"), "--registry", url], check=True,
                   capture_output=True)
    Approvals(Registry.open(url)).add_user("jdoe", "Jane Doe", "approver", PASSWORD)


def memory_kib(pid: int) -> dict[str, int]:
    fields = {}
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        key, _, value = line.partition(":")
        if key in ("VmRSS", "VmHWM"):
            fields[key] = int(value.split()[0])
    return {"rss_mib": fields.get("VmRSS", 0) // 1024, "peak_mib": fields.get("VmHWM", 0) // 1024}


async def load(base: str, args: argparse.Namespace) -> dict[str, Any]:
    """The load and the measurements, for `args.seconds`: the pages open over the first 2 s, the flood begins 1 s
    in, the measurements after WARM_UP_S (the server's first answers, its caches cold, are not the load's); each
    path's slowest answer is reported with when it was asked, seconds from the start."""
    limits = httpx.Limits(max_connections=None, max_keepalive_connections=None)
    timeout = httpx.Timeout(120.0)
    stop = asyncio.Event()
    async with httpx.AsyncClient(base_url=base, limits=limits, timeout=timeout) as client:
        answer = await client.get("/api/rigs")
        published = answer.json().get("campaigns", []) if answer.status_code == 200 else []
        live = f"/live/{published[0]['key']}" if published else "/live/" + "0" * 32   # silent: its 503, at once

        async def page(offset_s: float) -> None:  # an open front page: the rigs fragment and campaigns, every 2 s
            await asyncio.sleep(offset_s)          # opened at its own moment, as pages are
            while not stop.is_set():
                await client.get("/fragments/rigs")
                await client.get("/api/campaigns")
                await asyncio.sleep(2.0)

        async def stream() -> None:
            try:
                async with client.stream("GET", "/api/live/stream") as answer:
                    async for _ in answer.aiter_lines():
                        if stop.is_set():
                            return
            except httpx.HTTPError:
                return

        async def flood() -> None:
            login = await client.get("/login")
            token = login.text.split('name="csrf" value="')[1].split('"')[0] if 'name="csrf"' in login.text else ""
            await asyncio.gather(*(client.post("/login", data={"csrf": token, "name": "jdoe", "password": f"guess{k}"},
                                               headers={"origin": base}, cookies=login.cookies)
                                   for k in range(args.flood)))

        timings: dict[str, list[float]] = {"/": [], "live": [], "static": []}
        statuses: dict[str, dict[int, int]] = {name: {} for name in timings}
        slowest: dict[str, tuple[float, float]] = {name: (0.0, 0.0) for name in timings}  # (seconds, when)
        load_began = time.perf_counter()

        async def measure() -> None:
            paths = {"/": "/", "live": live, "static": "/static/dashboard.css"}
            await asyncio.sleep(WARM_UP_S)
            while not stop.is_set():
                for name, path in paths.items():
                    began = time.perf_counter()
                    answer = await client.get(path)
                    took = time.perf_counter() - began
                    timings[name].append(took)
                    if took > slowest[name][0]:
                        slowest[name] = (round(took, 4), round(began - load_began, 2))
                    statuses[name][answer.status_code] = statuses[name].get(answer.status_code, 0) + 1
                await asyncio.sleep(0.1)

        tasks = [asyncio.create_task(page(2.0 * k / args.pages)) for k in range(args.pages)]
        tasks += [asyncio.create_task(stream()) for _ in range(args.streams)]
        tasks.append(asyncio.create_task(measure()))
        await asyncio.sleep(1.0)
        flooded = asyncio.create_task(flood())
        await asyncio.sleep(args.seconds)
        stop.set()
        await flooded
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)

    def quantiles(values: list[float]) -> dict[str, float]:
        ordered = sorted(values)
        return {"n": len(ordered), "p50_s": round(statistics.median(ordered), 4),
                "p99_s": round(ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))], 4)} if ordered else {"n": 0}

    return {name: {**quantiles(values), "statuses": statuses[name],
                   "slowest": {"s": slowest[name][0], "at_s": slowest[name][1]}} for name, values in timings.items()}


def scenario(name: str, url: str, folder: Path, args: argparse.Namespace) -> dict[str, Any]:
    port = free_port()
    server = subprocess.Popen([RIG, "serve", "--campaigns", str(folder), "--port", str(port), "--registry", url],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                httpx.get(base + "/static/dashboard.css", timeout=2)
                break
            except httpx.HTTPError:
                if time.monotonic() > deadline or server.poll() is not None:
                    raise SystemExit(f"{name}: rig serve did not start: "
                                     f"{server.stderr.read() if server.stderr else ''}") from None
                time.sleep(0.2)
        measured = asyncio.run(load(base, args))
        return {"registry": name, **measured, "server_memory": memory_kib(server.pid)}
    finally:
        server.terminate()
        server.wait(timeout=30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pages", type=int, default=40)
    parser.add_argument("--streams", type=int, default=50)
    parser.add_argument("--flood", type=int, default=40)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--postgresql", help="a PostgreSQL server URL to create a database on (default: a private one)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    silence_campaign_log()
    results = []
    with tempfile.TemporaryDirectory() as folder_name:
        folder = Path(folder_name)
        sqlite = normalised(str(folder / "registry.sqlite"))
        filled(sqlite, folder)
        results.append(scenario("sqlite", sqlite, folder, args))
        private = PrivatePostgreSQL() if args.postgresql is None else None
        try:
            postgresql = fresh_database(args.postgresql or private.url)  # type: ignore[union-attr]
            filled(postgresql, folder)
            results.append(scenario("postgresql", postgresql, folder, args))
        finally:
            if private is not None:
                private.stop()
        silent = SilentServer()
        try:
            results.append(scenario("silent postgresql", f"postgresql+psycopg://lab@127.0.0.1:{silent.port}/registry",
                                    folder, args))
        finally:
            silent.close()
    report = {"pages": args.pages, "streams": args.streams, "flood": args.flood, "seconds": args.seconds,
              "results": results,
              "goal_front_p99_le_1s": all(r["/"].get("p99_s", 99) <= 1.0 for r in results)}
    if args.json:
        print(json.dumps(report, indent=1))
        return
    for r in results:
        print(f"{r['registry']:<18} " + "  ".join(
            f"{k} p50 {r[k]['p50_s'] * 1000:.0f} ms p99 {r[k]['p99_s'] * 1000:.0f} ms {r[k]['statuses']}"
            for k in ("/", "live", "static")) + f"  memory {r['server_memory']}")
    print(f"p99 of / ≤ 1 s everywhere: {report['goal_front_p99_le_1s']}")


if __name__ == "__main__":
    main()
