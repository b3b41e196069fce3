"""Is the stated uncertainty true? A Monte Carlo over repeated dry runs of the paper campaign (GUM
Supplement 1 style: the whole measurement repeated with new noise, the same simulated sensors): at every
verification pose, each axis's error of the compensated output against the simulation truth, against that
pose's expanded uncertainty (k = 2). The observed coverage should be 95 % (target 93–97 %).

Two sites: the shipped rig (the standard gravity, no stated uncertainty) and one whose gravity is stated
with an uncertainty (each run's simulated site drawn from it). Usage:

    python bench/uncertainty.py [--runs 10] [--json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np
import yaml
from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.store.read import load_campaign

REPO = Path(__file__).resolve().parent.parent
PAPER = REPO / "procedures" / "paper-24pos-thermal.yaml"
SITES = {"standard gravity": "", "site gravity 9.8123 ± 0.0002 m/s²": "gravity_m_s2: 9.8123\ngravity_uncertainty_m_s2: 0.0002\n"}


def procedure_for(folder: Path, name: str, rig_tail: str) -> Path:
    rig = folder / f"rig-{len(rig_tail)}.yaml"
    rig.write_text((REPO / "configs" / "sim.yaml").read_text() + rig_tail)
    procedure = yaml.safe_load(PAPER.read_text())
    procedure["rig"] = str(rig)
    path = folder / f"procedure-{len(rig_tail)}.yaml"
    path.write_text(yaml.safe_dump(procedure))
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    silence_campaign_log()
    results: dict[str, dict[str, object]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for site, rig_tail in SITES.items():
            procedure = procedure_for(folder, site, rig_tail)
            coverage: dict[str, list[float]] = defaultdict(list)
            expanded: dict[str, list[float]] = defaultdict(list)
            for seed in range(args.runs):
                output = folder / f"c{seed}.h5"
                run_campaign(prepare(procedure), output, dry_run=True, seed=seed, overwrite=True)
                campaign = load_campaign(output)
                for mode in ("reference", "norm-only"):
                    _, report = fit_campaign(campaign, FitOptions(mode=mode), {"campaign": str(output)})
                    for r in report.values():
                        coverage[mode].append(r["truth_coverage_k2"])
                        expanded[mode].append(max(r["expanded_uncertainty_mg"]))
            for mode in coverage:
                values = np.array(coverage[mode])
                results[f"{site}, {mode}"] = {
                    "observed_coverage_k2": float(values.mean()), "per_dut_min": float(values.min()),
                    "per_dut_max": float(values.max()), "dut_runs": len(values),
                    "expanded_uncertainty_mg_worst": float(max(expanded[mode])),
                }
    if args.json:
        print(json.dumps(results))
        return
    print(f"coverage of the k = 2 interval over {args.runs} dry runs × 4 DUTs × 168 verification poses × 3 axes "
          "(target 93–97 %; Gaussian 95.45 %)")
    for name, r in results.items():
        print(f"  {name:45s} {r['observed_coverage_k2'] * 100:.2f} % (per DUT and run {r['per_dut_min'] * 100:.1f} … "
              f"{r['per_dut_max'] * 100:.1f} %); expanded uncertainty up to {r['expanded_uncertainty_mg_worst']:.4f} mg")


if __name__ == "__main__":
    main()
