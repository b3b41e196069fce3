"""How a dry run's wall time grows with the fixture: the paper campaign (`procedures/paper-24pos-thermal.yaml`)
on the simulated rig with 4, 16, 32 and 64 DUTs (each behind its own simulated bridge on a pseudo-terminal,
mounted at one of four yaw angles), through the same drivers and wire simulators as `rig run --dry-run`, the
fit of every DUT included. Each size runs in a process of its own, timed on the wall clock. Usage:

    python bench/large_fixture.py [--sizes 4,16,32,64] [--json]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fixtures import write_procedure, write_rig  # bench/fixtures.py, beside this script
from quiet import throwaway_registry  # bench/quiet.py, beside this script

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")


def rig_with(duts: int, folder: Path) -> Path:
    """The shipped simulated rig with `duts` sensors; a copy of the paper procedure that names it."""
    write_rig(REPO / "configs" / "sim.yaml", duts, "ADX355-L", folder)
    return write_procedure(REPO / "procedures" / "paper-24pos-thermal.yaml", folder, "paper.yaml")


def timed_run(duts: int) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        procedure = rig_with(duts, folder)
        start = time.perf_counter()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run = subprocess.run([RIG, "run", str(procedure), "--dry-run", "-o", str(folder / "c.h5"), "-q", "--no-pdf"],
                             capture_output=True, text=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if run.returncode != 0:
            raise SystemExit(f"{duts} DUTs: rig run failed: {run.stderr.strip().splitlines()[-1]}")
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return {"duts": duts, "wall_s": wall, "cpu_s": cpu, "peak_rss_mb": after.ru_maxrss / 1024}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="4,16,32,64")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    throwaway_registry()
    results = [timed_run(int(n)) for n in args.sizes.split(",")]
    if args.json:
        print(json.dumps({"paper_dry_run": results}))
        return
    first = results[0]
    print("paper campaign dry run (432 poses) by fixture size, one process each, 2 cores:")
    for r in results:
        per_dut = r["wall_s"] / r["duts"]
        scale = r["wall_s"] / first["wall_s"]
        print(f"  {r['duts']:3d} DUTs: wall {r['wall_s']:6.1f} s ({per_dut:5.2f} s per DUT, {scale:4.1f}× the "
              f"{first['duts']}-DUT run for {r['duts'] / first['duts']:.0f}× the DUTs), cpu {r['cpu_s']:6.1f} s")


if __name__ == "__main__":
    main()
