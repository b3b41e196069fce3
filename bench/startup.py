"""Start-up of the `rig` command: wall time of `rig --help` and which heavy libraries it imports. Usage:

    python bench/startup.py --runs 20 [--json]

`rig --help` should import none of h5py, scipy, pyserial, pymodbus, matplotlib (nor numpy, pydantic, yaml):
the subcommands import what they need when they run.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

RIG = str(Path(sys.executable).parent / "rig")
HEAVY = ("h5py", "scipy", "serial", "pymodbus", "matplotlib", "numpy", "pydantic", "yaml")


def heavy_imports() -> list[str]:
    """Top-level heavy packages `rig --help` imports, from the interpreter's own import log."""
    run = subprocess.run([sys.executable, "-X", "importtime", RIG, "--help"], capture_output=True, text=True,
                         check=True)
    imported = {line.split("|")[-1].strip() for line in run.stderr.splitlines() if line.startswith("import time:")}
    return sorted(name for name in HEAVY if name in imported)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    walls = []
    for _ in range(args.runs + 1):  # the first run warms the file cache and is not counted
        start = time.perf_counter()
        subprocess.run([RIG, "--help"], capture_output=True, check=True)
        walls.append(time.perf_counter() - start)
    walls = walls[1:]
    heavy = heavy_imports()
    print(f"rig --help: median {statistics.median(walls) * 1e3:.0f} ms wall (min {min(walls) * 1e3:.0f}, "
          f"max {max(walls) * 1e3:.0f}) over {args.runs} runs; heavy libraries imported: {', '.join(heavy) or 'none'}")
    if args.json:
        print(json.dumps({"median_wall_ms": round(statistics.median(walls) * 1e3, 1), "heavy_imports": heavy}))


if __name__ == "__main__":
    main()
