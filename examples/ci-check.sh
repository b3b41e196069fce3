#!/usr/bin/env bash
# A part from outside the core, end to end: install the example plug-in package (examples/accelcal-rig-icm42605)
# into a venv where accelcal-rig is installed (from its wheel, not editable), dry-run the example's campaign from
# an empty temporary folder, and check that the campaign ended and that the plug-in part's DUTs were calibrated.
# Fails (non-zero) if the plug-in was not used: its part unknown, another part on the DUTs, a DUT not calibrated.
#
#   examples/ci-check.sh VENV
#
# The venv gains the package accelcal-rig-icm42605; nothing else is written outside a temporary folder (the dry
# run's registries included), which is removed at the end.
set -euo pipefail

if [ $# -ne 1 ]; then
    echo "usage: $0 VENV (a venv where accelcal-rig is installed)" >&2
    exit 2
fi
venv=$(cd "$1" && pwd)
python="$venv/bin/python"
rig="$venv/bin/rig"
example=$(cd "$(dirname "$0")/accelcal-rig-icm42605" && pwd)
[ -x "$rig" ] || { echo "$0: no rig in $venv/bin: install accelcal-rig there first" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Build from a copy: an in-tree build leaves build/ and *.egg-info in the repository.
cp -R "$example" "$work/source"
# --no-deps: the example's one dependency, accelcal-rig, is in the venv already (from its wheel) and on no package
# index, so pip must neither resolve nor upgrade it. The build itself needs setuptools (the example's
# build-system): where the venv can build a wheel offline (setuptools >= 70.1, or >= 64 with wheel) pip builds in
# the venv (--no-build-isolation, no index needed); else in an isolated environment with setuptools from the index.
isolation=()
if "$python" - <<'EOF'
import importlib.metadata as metadata
import sys

def version(name: str) -> tuple[int, ...]:
    try:
        return tuple(int(part) for part in metadata.version(name).split(".")[:2] if part.isdigit())
    except metadata.PackageNotFoundError:
        return ()

setuptools = version("setuptools")
sys.exit(0 if setuptools >= (70, 1) or (setuptools >= (64,) and version("wheel")) else 1)
EOF
then
    isolation=(--no-build-isolation)
fi
echo "installing $example into $venv (build: ${isolation[*]:-isolated})"
"$python" -m pip install --quiet --no-deps ${isolation[@]+"${isolation[@]}"} "$work/source"

# The dry run, from an empty folder; its calibrations go to registries of its own (never the user's).
mkdir "$work/run"
cd "$work/run"
export ACCELCAL_REGISTRY="$work/registry.sqlite" ACCELCAL_DRY_RUN_REGISTRY="$work/dry-runs.sqlite"
start=$(date +%s.%N)
status=0
"$rig" run "$example/quick-icm42605.yaml" --config "$example/sim-icm42605.yaml" --dry-run -o run.h5 --no-pdf \
    --fail-on-reject > run.log 2>&1 || status=$?
wall=$(awk -v start="$start" -v end="$(date +%s.%N)" 'BEGIN { printf "%.1f", end - start }')
if [ "$status" -ne 0 ]; then
    tail -n 30 run.log >&2
    echo "FAIL: rig run exited $status (${wall} s)" >&2
    exit 1
fi
"$rig" status run.h5 --json > status.json
grep -q "ICM-42605 (WHO_AM_I 0x42)" run.log || { echo "FAIL: no DUT answered as an ICM-42605" >&2; exit 1; }

# The campaign ended; every DUT is an ICM-42605 (the plug-in's part, from the installed package) and PASSes with
# both its accelerometer and its gyroscope calibrated.
"$python" - "$wall" <<'EOF'
import importlib
import json
import sys
from importlib.metadata import entry_points
from pathlib import Path

import h5py
import yaml

problems = []
entry = next((e for e in entry_points(group="accelcal_rig.parts") if e.name == "icm42605"), None)
if entry is None or entry.dist is None or entry.dist.name != "accelcal-rig-icm42605":
    problems.append(f"entry point icm42605 not from accelcal-rig-icm42605: {entry}")
elif "site-packages" not in Path(importlib.import_module(entry.module).__file__ or "").parts:
    problems.append(f"{entry.module} not imported from the venv's site-packages (an installed copy)")
status = json.loads(Path("status.json").read_text())
if status["state"] != "done" or status["poses_done"] != status["poses_total"] or not status["dry_run"]:
    problems.append(f"campaign {status['state']}, poses {status['poses_done']}/{status['poses_total']}")
duts = status["duts"]
with h5py.File("run.h5", "r") as campaign:
    parts = {serial: campaign[f"duts/{serial}"].attrs["part"] for serial in duts}
calibration = yaml.safe_load(Path(status["calibration"]).read_text())["duts"]
for serial in duts:
    verdict = status["verdicts"].get(serial, {})
    channels = sorted(calibration.get(serial, {}).get("channels", {}))
    if parts[serial] != "icm42605":
        problems.append(f"{serial}: part {parts[serial]!r}, not the plug-in's 'icm42605'")
    if verdict.get("verdict") != "PASS" or verdict.get("sensors") != {"accelerometer": "PASS", "gyroscope": "PASS"}:
        problems.append(f"{serial}: {verdict}")
    if channels != ["accel", "gyro"]:
        problems.append(f"{serial}: calibrated channels {channels}")
if len(duts) != 2:
    problems.append(f"{len(duts)} DUTs, the example's rig has 2")
if problems:
    print("FAIL:", *problems, sep="\n  ", file=sys.stderr)
    sys.exit(1)
print(f"OK: plug-in part icm42605 ({entry.dist.name} {entry.dist.version}) dry run: {status['procedure']} done, "
      f"{status['poses_done']} poses, {', '.join(f'{s} PASS' for s in duts)} (accel and gyro); {sys.argv[1]} s wall")
EOF
