"""The soak criteria compared: the paper's band (each DUT's readings within band_c over the window) and the
settling fit (what is still to come and the rate now, k = 2), at two poll rates and two fixture sizes, on
the paper campaign (`procedures/paper-24pos-thermal.yaml`) as a dry run. Usage:

    python bench/soak_criteria.py [--seed 0] [--duts 4,16] [--json]

Per run: the campaign's state, its total soak time and rig time, and the worst DUT's verification |g|
RMSE and residual drift (verification poses the fit never sees). A criterion that depends on the poll
rate soaks longer at the faster poll; one that depends on the fixture size, longer with more DUTs.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path
from typing import Any

import h5py
import yaml
from fixtures import write_procedure, write_rig  # bench/fixtures.py, beside this script
from quiet import silence_campaign_log, throwaway_registry  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import CampaignAborted
from accelcal_rig.fit.calibration import load_calibration

REPO = Path(__file__).resolve().parent.parent
#: Each criterion as the procedures have used it (the paper procedure's dwell, 30 min, for both).
CRITERIA = {
    "band": {"criterion": "band", "window_min": 10},
    "settling": {"criterion": "settling", "window_min": 20},
}


def run(criterion: str, poll_s: float, duts: int, seed: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        write_rig(REPO / "configs" / "sim.yaml", duts, "ADX355-S", folder)
        paper = REPO / "procedures" / "paper-24pos-thermal.yaml"
        soak = {**yaml.safe_load(paper.read_text())["soak"], **CRITERIA[criterion], "poll_s": poll_s}
        path = write_procedure(paper, folder, "paper.yaml", soak=soak)
        output = folder / "campaign.h5"
        calibration = output.with_suffix(".calibration.yaml")
        record: dict[str, Any] = {"criterion": criterion, "poll_s": poll_s, "n_duts": duts, "seed": seed}
        try:
            summary = run_campaign(prepare(path), output, dry_run=True, seed=seed, overwrite=False,
                                   calibration=calibration).summary
            record |= {"state": summary.state, "rig_hours": summary.virtual_duration_s / 3600}
        except CampaignAborted as exc:
            record |= {"state": f"aborted: {exc}"}
        with h5py.File(output, "r") as f:
            soaks = [g for g in f["soaks"].values()]
            record["soak_hours"] = sum(float(g["t_s"][-1] - g.attrs["t_reached_s"]) for g in soaks) / 3600
            record["soak_minutes"] = [round(float(g["t_s"][-1] - g.attrs["t_reached_s"]) / 60, 1) for g in soaks]
        if calibration.is_file() and record["state"] == "done":
            checks = [s.metrics["verification"] for s in load_calibration(calibration).of_quantity("acceleration").values()]
            record["verification_rmse_mg"] = max(v["rmse_mg"] for v in checks)
            record["residual_drift_mg"] = max(max(v["drift_mg"]) for v in checks)
        return record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--duts", default="4,16")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    silence_campaign_log()
    throwaway_registry()
    records = [run(criterion, poll_s, int(duts), args.seed) for duts in args.duts.split(",")
               for criterion in CRITERIA for poll_s in (30.0, 10.0)]
    if args.json:
        print(json.dumps({"runs": records}))
        return
    for r in records:
        quality = (f"verification RMSE {r['verification_rmse_mg']:.4f} mg, drift {r['residual_drift_mg']:.4f} mg"
                   if "verification_rmse_mg" in r else "no calibration")
        print(f"{r['criterion']:>8} poll {r['poll_s']:>4.0f} s, {r['n_duts']:>2} DUTs: {r['state']}; soaks "
              f"{r['soak_hours']:.2f} h (longest {max(r['soak_minutes']):.0f} min); {quality}")


if __name__ == "__main__":
    main()
