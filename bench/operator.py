"""Figures of the operator's tools: how close `rig plan`'s estimate comes to what dry runs take on their
clock, what the progress display costs a dry run, and how long `rig plan` and `rig report` take. Usage:

    python bench/operator.py [--seeds 5]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
from quiet import silence_campaign_log, throwaway_registry  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.report.live import ProgressLines

REPO = Path(__file__).resolve().parent.parent
PROCEDURES = [REPO / "procedures" / "paper-24pos-thermal.yaml", REPO / "procedures" / "quick-6pos.yaml"]
RIG = Path(sys.executable).parent / "rig"


def estimate_against_dry_runs(seeds: int, folder: Path) -> None:
    print("estimate against dry runs (virtual campaign time)")
    for procedure in PROCEDURES:
        prepared = prepare(procedure)
        estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan).total_s
        errors = []
        for seed in range(seeds):
            output = folder / f"{procedure.stem}-{seed}.h5"
            took = run_campaign(prepared, output, dry_run=True, seed=seed, overwrite=True).summary.virtual_duration_s
            errors.append((estimate - took) / took * 100)
            print(f"  {procedure.stem:20s} seed {seed}: estimate {format_duration(estimate)}  dry run "
                  f"{format_duration(took)}  error {errors[-1]:+.2f} %")
        print(f"  {procedure.stem:20s} error mean {statistics.mean(errors):+.2f} %, worst "
              f"{max(errors, key=abs):+.2f} %")


def progress_cost(runs: int, folder: Path) -> None:
    """Wall time of the paper dry run with and without the progress listener, interleaved."""
    prepared = prepare(PROCEDURES[0])
    walls: dict[str, list[float]] = {"without": [], "with": []}
    for _ in range(runs):
        for kind in walls:
            progress = ProgressLines(real_clock=False) if kind == "with" else None
            result = run_campaign(prepared, folder / "progress.h5", dry_run=True, seed=0, overwrite=True,
                                  progress=progress)
            walls[kind].append(result.wall_s)
    print(f"paper dry run wall, median of {runs}: without progress {statistics.median(walls['without']):.2f} s, "
          f"with progress lines {statistics.median(walls['with']):.2f} s")


def command_times(folder: Path) -> None:
    started = time.perf_counter()
    subprocess.run([str(RIG), "plan", str(PROCEDURES[0])], check=True, capture_output=True)
    print(f"rig plan (paper campaign, whole process): {time.perf_counter() - started:.2f} s")
    campaign = folder / f"{PROCEDURES[0].stem}-0.h5"
    started = time.perf_counter()
    subprocess.run([str(RIG), "report", str(campaign), "-o", str(folder / "report")], check=True, capture_output=True)
    sizes = {p.name: p.stat().st_size for p in (folder / "report" / "figures").iterdir()}
    print(f"rig report (paper campaign, whole process): {time.perf_counter() - started:.2f} s; figures "
          + ", ".join(f"{name} {size / 1e3:.0f} kB" for name, size in sorted(sizes.items())))
    with h5py.File(campaign, "r") as file:
        print(f"  (campaign file {campaign.stat().st_size / 1e6:.1f} MB, {file['poses/step_key'].shape[0]} poses)")


def main() -> None:
    throwaway_registry()
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args()
    silence_campaign_log()
    with tempfile.TemporaryDirectory() as folder:
        estimate_against_dry_runs(args.seeds, Path(folder))
        progress_cost(3, Path(folder))
        command_times(Path(folder))


if __name__ == "__main__":
    main()
