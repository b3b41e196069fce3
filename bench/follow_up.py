"""A campaign's follow-up under kill -9: `rig run` killed at every write system call after its last pose (the
fit stage, the campaign file, the certificates, the registry's SQLite writes, the progress file), each
trial then finished by one `rig resume`. Usage:

    python bench/follow_up.py [--procedure procedures/quick-6pos.yaml] [--pdf] [--workers 2] [--step 1] [--json]

The kill points: an uninterrupted run's own system calls (its main thread, `strace -y`), from the journal
write that follows the last pose to the exit, every one of WRITE_CALLS; a trial kills the run when it
enters that call (strace's injection counts per call and per thread: the main thread's n-th call of its
kind). A trial passes when, after the kill and one `rig resume` (exit 0):

- every pose of the plan is stored once (the kill came after the last pose: checked, not assumed);
- the calibration file is there and fitted to the campaign's measurements;
- every DUT's certificate is there and written from that calibration (its page names the calibration's
  certificate number; with --pdf, its PDF beside it);
- the registry holds every DUT's row exactly once (`SELECT serial, count(*) … GROUP BY serial`);
- `rig status --json` then says every part of the follow-up is done.

Without --pdf the certificates are HTML only (PDFs are written the same way, a temporary file renamed,
before their page; rendering them adds seconds of CPU to every trial). Needs strace.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import sqlite3
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")
WRITE_CALLS = ("write", "pwrite64", "fsync", "fdatasync", "rename", "unlink")
#: The journal record written after the last pose names the transition to the safe state with this.
AFTER_LAST_POSE = "(campaign complete)"


def run_argv(procedure: Path, folder: Path, pdf: bool) -> list[str]:
    return [RIG, "run", str(procedure), "--dry-run", "-o", str(folder / "c.h5"), "-q", *([] if pdf else ["--no-pdf"])]


def environment(folder: Path) -> dict[str, str]:
    """Each trial's own dry-run registry, and no registry of the user's touched."""
    return {**os.environ, "ACCELCAL_DRY_RUN_REGISTRY": str(folder / "registry.sqlite"),
            "ACCELCAL_REGISTRY": str(folder / "lab-registry.sqlite"), "PYTHONUNBUFFERED": "1"}


def kill_points(procedure: Path, folder: Path, pdf: bool) -> list[tuple[str, int]]:
    """(call, n) for every write call of the main thread after the last pose of an uninterrupted run."""
    folder.mkdir(parents=True, exist_ok=True)
    trace = folder / "trace.txt"
    subprocess.run(["strace", "-y", "-s", "400", "-o", str(trace), "-e", f"trace={','.join(WRITE_CALLS)}",
                    *run_argv(procedure, folder, pdf)], env=environment(folder), capture_output=True, check=True)
    seen: dict[str, int] = {}
    points: list[tuple[str, int]] = []
    after = False
    for line in trace.read_text(errors="replace").splitlines():
        match = re.match(r"(\w+)\(", line)
        if match is None or match.group(1) not in WRITE_CALLS:
            continue
        call = match.group(1)
        seen[call] = seen.get(call, 0) + 1
        if not after and ".journal>" in line and AFTER_LAST_POSE in line:
            after = True
        if after:
            points.append((call, seen[call]))
    if not points:
        raise SystemExit(f"no journal write naming {AFTER_LAST_POSE!r} in {trace}: the marker changed")
    return points


def trial(procedure: Path, folder: Path, pdf: bool, call: str, when: int) -> dict[str, object]:
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    env = environment(folder)
    killed = subprocess.run(["strace", "-o", "/dev/null", "-e", f"trace={call}", "-e",
                             f"inject={call}:signal=SIGKILL:when={when}", *run_argv(procedure, folder, pdf)],
                            env=env, capture_output=True, text=True, timeout=600)
    campaign = folder / "c.h5"
    resumed = subprocess.run([RIG, "resume", str(campaign), "-q"], env=env, capture_output=True, text=True,
                             timeout=600)
    result: dict[str, object] = {"call": call, "when": when, "killed": killed.returncode != 0,
                                 "resume_exit": resumed.returncode}
    status = subprocess.run([RIG, "status", str(campaign), "--json"], env=env, capture_output=True, text=True)
    found = json.loads(status.stdout) if status.returncode == 0 else {}
    result["poses"] = f"{found.get('poses_done')}/{found.get('poses_total')}"
    result["follow_up"] = {p["part"]: p["state"] for p in found.get("follow_up", [])}
    result["rows"] = registry_rows(folder / "registry.sqlite")
    duts = found.get("duts") or []
    result["ok"] = bool(resumed.returncode == 0 and found.get("state") == "done"
                        and found.get("poses_done") == found.get("poses_total")
                        and result["follow_up"] == {"calibration": "done", "certificates": "done", "registry": "done"}
                        and sorted(result["rows"]) == sorted(duts) and set(result["rows"].values()) == {1})
    if not result["ok"]:
        result["stderr"] = (resumed.stderr.strip().splitlines() or [""])[-1][:300]
    return result


def registry_rows(path: Path) -> dict[str, int]:
    """Rows per serial in a registry file (none if there is none)."""
    if not path.is_file():
        return {}
    with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as connection:
        return dict(connection.execute("SELECT serial, count(*) FROM calibrations GROUP BY serial").fetchall())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--procedure", type=Path, default=REPO / "procedures" / "quick-6pos.yaml")
    parser.add_argument("--pdf", action="store_true", help="PDF certificates too")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--step", type=int, default=1, help="every STEP-th kill point only (a quick look; 1: all)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    if shutil.which("strace") is None:
        sys.exit("needs strace (apt-get install strace)")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        points = kill_points(args.procedure, root / "trace", args.pdf)[::args.step]
        print(f"{len(points)} write calls after the last pose: "
              + ", ".join(f"{c} {sum(1 for p in points if p[0] == c)}" for c in WRITE_CALLS), flush=True)

        def one(k: int) -> dict[str, object]:
            result = trial(args.procedure, root / f"t{k % args.workers}-{k}", args.pdf, *points[k])
            if not args.json:
                print(f"{points[k][0]:9s} #{points[k][1]:5d}: {'pass' if result['ok'] else 'FAIL'}  "
                      f"killed {result['killed']}, poses {result['poses']}, resume exit {result['resume_exit']}, "
                      f"{result['follow_up']}, rows {result['rows']} {result.get('stderr', '')}", flush=True)
            shutil.rmtree(root / f"t{k % args.workers}-{k}", ignore_errors=True)
            return result

        with ThreadPoolExecutor(args.workers) as pool:
            results = list(pool.map(one, range(len(points))))
    passed = sum(1 for r in results if r["ok"])
    killed = sum(1 for r in results if r["killed"])
    print(f"follow-up kills: {passed}/{len(results)} trials passed ({killed} runs killed; the others ended "
          "before the call came)")
    if args.json:
        print(json.dumps({"trials": len(results), "passed": passed, "killed": killed,
                          "failed": [r for r in results if not r["ok"]]}))
    sys.exit(0 if passed == len(results) else 1)


if __name__ == "__main__":
    main()
