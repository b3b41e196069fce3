"""Wall time, peak memory, virtual duration and file size of the paper campaign's dry run.

Runs `rig run procedures/paper-24pos-thermal.yaml --dry-run` as a separate process several times (as a
user would) and prints one line per run and a summary. Usage:

    python bench/dry_run_paper.py [--runs 3] [--procedure procedures/paper-24pos-thermal.yaml]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def run_once(procedure: Path, output: Path, seed: int) -> tuple[float, float, dict]:
    """(wall seconds, peak RSS of this child in MB, status) for one CLI run."""
    rig = Path(sys.executable).parent / "rig"
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)  # keep the bench's own output to one line per run
        os.execv(str(rig), [str(rig), "run", str(procedure), "--dry-run", "-o", str(output), "--seed", str(seed),
                            "-q", "--overwrite"])
    _, status, usage = os.wait4(pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"run failed with exit code {os.waitstatus_to_exitcode(status)}")
    report = json.loads(subprocess.run([str(rig), "status", str(output), "--json"], capture_output=True,
                                       text=True, check=True).stdout)
    return wall, usage.ru_maxrss / 1024, report


def virtual_duration_h(output: Path) -> float:
    import h5py

    with h5py.File(output, "r") as f:
        return float(f["poses/t_end_s"][-1]) / 3600


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--procedure", type=Path, default=REPO / "procedures" / "paper-24pos-thermal.yaml")
    args = parser.parse_args()
    walls = []
    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "campaign.h5"
        for seed in range(args.runs):
            wall, peak_mb, report = run_once(args.procedure, output, seed)
            walls.append(wall)
            print(f"run {seed}: wall {wall:.2f} s, peak RSS {peak_mb:.0f} MB, "
                  f"{report['poses_done']}/{report['poses_total']} poses × {len(report['duts'])} DUTs, "
                  f"virtual {virtual_duration_h(output):.2f} h, file {output.stat().st_size / 1e6:.2f} MB")
    print(f"summary: wall median {sorted(walls)[len(walls) // 2]:.2f} s (min {min(walls):.2f}, max {max(walls):.2f}) "
          f"over {len(walls)} runs on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
