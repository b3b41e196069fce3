"""The ramp method against the soak method on the same simulated sensors: how good each calibration is,
against the hidden truth, and how much rig time each campaign takes. Usage:

    python bench/ramp_vs_soak.py [--seeds 3]

Quality: the calibration applied to what each sensor would read at 500 orientations × every 1 °C from the
lowest to the highest calibrated temperature; the error is the compensated reading minus the true specific
force (mg), and the worst parameter errors of the polynomials against the truth.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import warnings
from pathlib import Path

import numpy as np
from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.calibration import CalibrationRangeWarning, apply, load_calibration
from accelcal_rig.fit.sfem import distort
from accelcal_rig.plan.schedules import sphere
from accelcal_rig.sim.truth import truth_for_serial

REPO = Path(__file__).resolve().parent.parent
METHODS = {"soak": REPO / "procedures" / "paper-24pos-thermal.yaml",
           "ramp": REPO / "procedures" / "paper-24pos-ramp.yaml"}


def quality(calibration_path: Path) -> dict[str, float]:
    calibration = load_calibration(calibration_path)
    directions = sphere(500)
    errors, bias, scale = [], [], []
    for serial, sensor in calibration.of_quantity("acceleration").items():
        temperatures = np.arange(np.ceil(sensor.validity_c[0]), np.floor(sensor.validity_c[1]) + 1)
        truth = truth_for_serial(serial).parameters_at(temperatures)          # (T, 12)
        fitted = sensor.parameters_at(temperatures)
        raw = distort(directions[None, :, :], truth[:, None, :])              # (T, 500, 3)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CalibrationRangeWarning)
            compensated = apply(sensor, raw, np.repeat(temperatures[:, None], len(directions), axis=1))
        errors.append(np.abs(compensated - directions).max() * 1e3)
        bias.append(np.abs(fitted[:, 0:3] - truth[:, 0:3]).max() * 1e6)
        scale.append(np.abs(fitted[:, 3:6] - truth[:, 3:6]).max() * 1e6)
    return {"worst_error_mg": max(errors), "worst_bias_ug": max(bias), "worst_scale_ppm": max(scale)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args()
    silence_campaign_log()
    results: dict[str, list[dict[str, float]]] = {m: [] for m in METHODS}
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(args.seeds):
            for method, procedure in METHODS.items():
                output = Path(folder) / f"{method}-{seed}.h5"
                calibration = output.with_suffix(".calibration.yaml")
                run = run_campaign(prepare(procedure), output, dry_run=True, seed=seed, overwrite=True,
                                   calibration=calibration)
                figures = quality(calibration) | {"hours": run.summary.virtual_duration_s / 3600,
                                                  "poses": run.summary.poses_done, "wall_s": run.wall_s}
                results[method].append(figures)
                print(f"seed {seed} {method}: {format_duration(run.summary.virtual_duration_s)} of rig time, "
                      f"{run.summary.poses_done} poses; worst compensated error {figures['worst_error_mg']:.4f} mg, "
                      f"bias {figures['worst_bias_ug']:.1f} µg, scale {figures['worst_scale_ppm']:.1f} ppm")
    for method, rows in results.items():
        mean = {k: statistics.mean(r[k] for r in rows) for k in rows[0]}
        worst = {k: max(r[k] for r in rows) for k in rows[0]}
        print(f"{method}: rig time {mean['hours']:.2f} h; worst compensated error mean {mean['worst_error_mg']:.4f} mg "
              f"(worst {worst['worst_error_mg']:.4f}); bias error ≤ {worst['worst_bias_ug']:.1f} µg; scale error ≤ "
              f"{worst['worst_scale_ppm']:.1f} ppm; wall {mean['wall_s']:.1f} s")
    saved = 1 - statistics.mean(r["hours"] for r in results["ramp"]) / statistics.mean(r["hours"] for r in results["soak"])
    print(f"ramp saves {saved * 100:.0f} % of the rig time")


if __name__ == "__main__":
    main()
