"""Sixteen IMUs in one thermal cycle: rig time and accuracy of the fast method against the soak method, on the
same simulated rig with the honest physics on. Usage:

    python bench/imu_throughput.py [--quick] [--seeds 3] [--methods fast,soak] [--json]

Each method's shipped procedure is run as a dry run on `configs/sim-imu16.yaml` (sixteen ICM-42688-P on a rate
table; the chamber's overshoot and its cooling slowing towards the compressor's floor, slot-to-slot air
differences, a fixture lagging more with more DUTs: docs/procedures.md, "Honest physics"), the accelerometers
given the effects Eq. 1 does not hold (`bench/throughput.py`'s SENSOR_EFFECTS: hysteresis relaxing over hours,
bias and scale by the rate of temperature change). The gyroscopes' simulated effects are their hidden thermal
model, white noise and the 5 °/h bias wander of the rig config; the simulator gives them no hysteresis and no
rate-of-change term. No acceptance limits: the figures, not a verdict. Methods: `fast`
(procedures/imu-fast.yaml, the bidirectional ramp with poses and rate steps in every band) and `soak`
(procedures/imu-thermal.yaml, the paper's soak at every setpoint) on that rig.

Per run, over its sixteen IMUs: `rig_hours` (first ramp to last record); for each sensor the verification RMSE
over its expected RMSE (`verification.expected_rmse_*`: what the noise alone would leave on the checks, each
check's own and the calibration's carried to it), its median and worst IMU, and the k = 2 coverage
of the verification records' errors against the simulation's truth, pooled over the IMUs (their mean). The
seeds' figures are reported each, with their worst. `--json`: one JSON object, `{"runs": [...], "methods":
{...}}`. Targets (issue 39): ≤ 6 h of rig time; every IMU ≤ 1.2 × for both sensors; coverage 93–97 % for both.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from fixtures import write_procedure  # bench/fixtures.py, beside this script
from quiet import silence_campaign_log, throwaway_registry  # bench/quiet.py, beside this script
from throughput import SENSOR_EFFECTS  # bench/throughput.py: the accelerometers' honest effects

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.calibration import load_calibration

REPO = Path(__file__).resolve().parent.parent
RIG = REPO / "configs" / "sim-imu16.yaml"
METHODS = {"fast": REPO / "procedures" / "imu-fast.yaml", "soak": REPO / "procedures" / "imu-thermal.yaml"}
#: Each sensor's figures: its quantity, its verification RMSE's key and its expected fit RMSE's.
SENSORS = {"accel": ("acceleration", "rmse_mg", "expected_rmse_mg"),
           "gyro": ("angular rate", "rmse_dps", "expected_rmse_dps")}


def variant(method: str, folder: Path) -> Path:
    """The method's procedure on the sixteen-IMU rig with the accelerometers' effects and no limits."""
    shutil.copyfile(RIG, folder / "rig.yaml")
    return write_procedure(METHODS[method], folder, f"{method}.yaml", simulation=SENSOR_EFFECTS, acceptance={})


def sensor_figures(calibration_path: Path, quantity: str, rmse_key: str, expected_key: str) -> dict[str, Any]:
    """One sensor's figures over the IMUs: the ratio of each, its median and worst, the pooled coverage."""
    channels = load_calibration(calibration_path).of_quantity(quantity)
    ratios = {serial: c.metrics["verification"][rmse_key] / c.metrics["verification"][expected_key] for serial, c in channels.items()}
    coverage = [c.metrics["truth_coverage_k2"] for c in channels.values() if "truth_coverage_k2" in c.metrics]
    worst = max(ratios, key=lambda serial: ratios[serial])
    return {"imus": len(channels), "ratio_median": statistics.median(ratios.values()), "ratio_worst": ratios[worst],
            "worst_imu": worst, "coverage_k2": statistics.fmean(coverage) if coverage else None,
            "coverage_k2_lowest_imu": min(coverage) if coverage else None}


def run(method: str, seed: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        prepared = prepare(variant(method, folder))
        output = folder / "campaign.h5"
        calibration_path = output.with_suffix(".calibration.yaml")
        started = time.perf_counter()
        result = run_campaign(prepared, output, dry_run=True, seed=seed, overwrite=False,
                              calibration=calibration_path)
        wall_s = time.perf_counter() - started
        sensors = {name: sensor_figures(calibration_path, *keys) for name, keys in SENSORS.items()}
    return {"method": method, "seed": seed, "state": result.summary.state,
            "rig_hours": result.summary.virtual_duration_s / 3600, "wall_s": wall_s, **sensors}


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """A method's figures over its seeds: the median rig time, and each sensor's worst over the seeds."""
    out: dict[str, Any] = {"seeds": len(runs), "rig_hours_median": statistics.median(r["rig_hours"] for r in runs),
                           "rig_hours_worst": max(r["rig_hours"] for r in runs)}
    for name in SENSORS:
        figures = [r[name] for r in runs]
        out[name] = {"ratio_worst": max(f["ratio_worst"] for f in figures),
                     "ratio_median_of_medians": statistics.median(f["ratio_median"] for f in figures),
                     "coverage_k2_range": [min(f["coverage_k2"] for f in figures),
                                           max(f["coverage_k2"] for f in figures)]}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="one seed")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--methods", default="fast,soak", help="comma-separated, of: " + ", ".join(METHODS))
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    silence_campaign_log()
    throwaway_registry()
    seeds = range(1 if args.quick else args.seeds)
    runs = [run(method, seed) for method in args.methods.split(",") for seed in seeds]
    methods = {m: summary([r for r in runs if r["method"] == m]) for m in args.methods.split(",")}
    if args.json:
        print(json.dumps({"rig": str(RIG.relative_to(REPO)), "sensor_effects": SENSOR_EFFECTS, "runs": runs,
                          "methods": methods}))
        return
    print(f"sixteen IMUs on {RIG.relative_to(REPO)}, honest physics and the accelerometers' effects on:")
    for r in runs:
        line = f"  {r['method']:>4} seed {r['seed']}: {r['state']}, rig {r['rig_hours']:.2f} h ({r['wall_s']:.0f} s wall)"
        for name in SENSORS:
            f = r[name]
            line += (f"; {name} ×{f['ratio_median']:.2f} median, ×{f['ratio_worst']:.2f} worst ({f['worst_imu']}), "
                     f"coverage {f['coverage_k2']:.3f}")
        print(line)


if __name__ == "__main__":
    main()
