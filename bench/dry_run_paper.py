"""Wall time, peak memory, virtual duration and file size of the paper campaign's dry run.

Two measurements. (1) `rig run procedures/paper-24pos-thermal.yaml --dry-run` as a separate process, as a
user runs it: the real drivers talking to wire-level simulators (Modbus TCP on loopback, pseudo-terminals).
(2) The campaign alone (run_campaign, imports excluded) through those wires against the in-process
simulated instruments. Usage:

    python bench/dry_run_paper.py [--runs 3] [--json]

`--json`: one JSON object instead of the lines: each process run's wall time, peak RSS, virtual hours
and file size, their median wall, and the campaign alone through the wire and in-process with the ratio
of their medians.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from quiet import silence_campaign_log, throwaway_registry  # bench/quiet.py, beside this script

REPO = Path(__file__).resolve().parent.parent
PAPER = REPO / "procedures" / "paper-24pos-thermal.yaml"


def cli_run(output: Path, seed: int) -> tuple[float, float, dict]:
    """(wall seconds, peak RSS of the process in MB, status) for one `rig run` process."""
    rig = Path(sys.executable).parent / "rig"
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)  # keep the bench's own output to one line per run
        os.execv(str(rig), [str(rig), "run", str(PAPER), "--dry-run", "-o", str(output), "--seed", str(seed),
                            "-q", "--overwrite"])
    _, status, usage = os.wait4(pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"run failed with exit code {os.waitstatus_to_exitcode(status)}")
    report = json.loads(subprocess.run([str(rig), "status", str(output), "--json"], capture_output=True,
                                       text=True, check=True).stdout)
    return wall, usage.ru_maxrss / 1024, report


def campaign_only(output: Path, seed: int, in_process: bool) -> float:
    from accelcal_rig.assembly import in_process_simulation, run_campaign
    from accelcal_rig.engine import session
    from accelcal_rig.engine.preparation import prepare

    prepared = prepare(PAPER)
    start = time.perf_counter()
    calibration = output.with_suffix(".calibration.yaml")
    if in_process:
        session.run_campaign(prepared, output, in_process_simulation(prepared), seed=seed, overwrite=True,
                             calibration=calibration)
    else:
        run_campaign(prepared, output, dry_run=True, seed=seed, overwrite=True, calibration=calibration)
    return time.perf_counter() - start


def main() -> None:
    throwaway_registry()
    import h5py

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--json", action="store_true", help="one JSON object instead of the lines")
    args = parser.parse_args()
    silence_campaign_log()
    median = lambda values: sorted(values)[len(values) // 2]  # noqa: E731

    def say(line: str) -> None:  # the lines, unless the JSON object is asked for
        if not args.json:
            print(line)

    runs = []
    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "campaign.h5"
        for seed in range(args.runs):
            wall, peak_mb, report = cli_run(output, seed)
            with h5py.File(output, "r") as f:
                virtual_h = float(f["poses/t_end_s"][-1]) / 3600
                chamber = f["instruments/chamber"].attrs["driver"]
            runs.append({"seed": seed, "wall_s": round(wall, 2), "peak_rss_mb": round(peak_mb), "virtual_h": round(virtual_h, 2),
                         "file_mb": round(output.stat().st_size / 1e6, 2), "poses": report["poses_done"],
                         "duts": len(report["duts"])})
            say(f"rig run (process, {chamber} over the wire) {seed}: wall {wall:.2f} s, peak RSS {peak_mb:.0f} MB, "
                f"{report['poses_done']}/{report['poses_total']} poses × {len(report['duts'])} DUTs, "
                f"virtual {virtual_h:.2f} h, file {output.stat().st_size / 1e6:.2f} MB")
        walls = [r["wall_s"] for r in runs]
        say(f"summary: process wall median {median(walls):.2f} s (min {min(walls):.2f}, "
            f"max {max(walls):.2f}) over {len(walls)} runs on {os.cpu_count()} cores")
        wire, local = [], []
        for seed in range(args.runs):  # interleaved, so a busier spell of the machine hits both alike
            wire.append(campaign_only(output, seed, in_process=False))
            local.append(campaign_only(output, seed, in_process=True))
        say(f"campaign alone (incl. fit): through the wire median {median(wire):.2f} s, in-process "
            f"median {median(local):.2f} s, ratio {median(wire) / median(local):.2f}")
    if args.json:
        print(json.dumps({"runs": runs, "wall_median_s": median(walls),
                          "campaign_alone": {"wire_s": [round(w, 2) for w in wire], "in_process_s": [round(s, 2) for s in local],
                                             "wire_median_s": round(median(wire), 2),
                                             "in_process_median_s": round(median(local), 2),
                                             "ratio": round(median(wire) / median(local), 3)}}))

if __name__ == "__main__":
    main()
