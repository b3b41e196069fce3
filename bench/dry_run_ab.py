"""Two dry runs compared in the same hour: `rig run A --dry-run` and `rig run B --dry-run` as processes, as a
user runs them, alternated pair by pair so that a busier spell of the machine hits both alike; the wall time
and peak memory of each, their medians and the ratio A/B pair by pair. Default A: the paper campaign on four
ICM-42688-P (procedures/paper-24pos-imu.yaml, the FIFO captured by the bridge), B: the same campaign on four
ADXL355 (procedures/paper-24pos-thermal.yaml); issue 39's bound: A within 2 × B. Usage:

    python bench/dry_run_ab.py [--runs 3] [--seed 11] [--a PROCEDURE] [--b PROCEDURE] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from quiet import throwaway_registry  # bench/quiet.py, beside this script

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")


def dry_run(procedure: Path, output: Path, seed: int) -> dict[str, float]:
    """One `rig run --dry-run` process: its wall seconds and peak resident memory (MiB)."""
    with tempfile.TemporaryFile("w+") as stderr:  # a file, not a pipe: waited on by wait4, nobody drains a pipe
        start = time.perf_counter()
        process = subprocess.Popen([RIG, "run", str(procedure), "--dry-run", "-o", str(output), "--overwrite",
                                    "--no-pdf", "--no-publish", "-q", "--seed", str(seed)],
                                   stdout=subprocess.DEVNULL, stderr=stderr)
        _, status, usage = os.wait4(process.pid, 0)   # this process's own peak memory, not the children's largest
        wall_s = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        if process.returncode != 0:
            stderr.seek(0)
            error = stderr.read().strip().splitlines()
            raise SystemExit(f"{procedure.name}: rig run exit {process.returncode}: {error[-1] if error else ''}")
    return {"wall_s": round(wall_s, 2), "peak_mib": round(usage.ru_maxrss / 1024, 1)}


def shown(path: Path) -> str:
    """A procedure's path as the repository names it, or as given when it is outside."""
    resolved = path.resolve()
    return resolved.relative_to(REPO).as_posix() if resolved.is_relative_to(REPO) else str(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3, help="pairs")
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--a", type=Path, default=REPO / "procedures" / "paper-24pos-imu.yaml")
    parser.add_argument("--b", type=Path, default=REPO / "procedures" / "paper-24pos-thermal.yaml")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    throwaway_registry()
    pairs = []
    with tempfile.TemporaryDirectory() as folder:
        for k in range(args.runs):
            a = dry_run(args.a, Path(folder) / "a.h5", args.seed)
            b = dry_run(args.b, Path(folder) / "b.h5", args.seed)
            pairs.append({"a": a, "b": b, "ratio": round(a["wall_s"] / b["wall_s"], 3)})
            if not args.json:
                print(f"pair {k}: A {a['wall_s']:.1f} s ({a['peak_mib']:.0f} MiB), B {b['wall_s']:.1f} s "
                      f"({b['peak_mib']:.0f} MiB), A/B {pairs[-1]['ratio']:.2f}", flush=True)
    ratios = [p["ratio"] for p in pairs]
    figures = {"a": shown(args.a), "b": shown(args.b),
               "seed": args.seed, "pairs": pairs,
               "a_wall_median_s": statistics.median(p["a"]["wall_s"] for p in pairs),
               "b_wall_median_s": statistics.median(p["b"]["wall_s"] for p in pairs),
               "a_peak_median_mib": statistics.median(p["a"]["peak_mib"] for p in pairs),
               "b_peak_median_mib": statistics.median(p["b"]["peak_mib"] for p in pairs),
               "ratio_median": statistics.median(ratios), "ratio_range": [min(ratios), max(ratios)]}
    if args.json:
        print(json.dumps(figures))
        return
    print(f"A {figures['a']} against B {figures['b']}, {len(pairs)} pairs: wall median {figures['a_wall_median_s']:.1f} s "
          f"against {figures['b_wall_median_s']:.1f} s, ratio A/B median {figures['ratio_median']:.2f} "
          f"({min(ratios):.2f} … {max(ratios):.2f})")


if __name__ == "__main__":
    main()
