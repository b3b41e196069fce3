"""Accuracy and speed of the calibration math on dry runs of the paper campaign.

For several seeds (same simulated sensors, new noise): the verification poses' |g| RMSE against the noise
floor and their residual drift (the held-out figures), the in-sample RMSE against the expected fit RMSE,
truth errors against their 1σ, and a Monte Carlo of the estimates' scatter against the
quoted 1σ; then fit times; then the same campaign with unmodelled effects switched on. Usage:

    python bench/fit_accuracy.py [--seeds 10]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import yaml
from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.acceleration import ACCELERATION, accelerometer_poses
from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.fit.vector_model import fit_vector
from accelcal_rig.store.read import load_campaign

REPO = Path(__file__).resolve().parent.parent
PAPER = REPO / "procedures" / "paper-24pos-thermal.yaml"
MODES = ("reference", "norm-only")


def dry_run(procedure: Path, folder: Path, seed: int) -> Path:
    output = folder / f"campaign-{procedure.stem}-{seed}.h5"
    run_campaign(prepare(procedure), output, dry_run=True, seed=seed, overwrite=True)
    return output


def accuracy(seeds: int, folder: Path) -> None:
    ratios, drifts = defaultdict(list), defaultdict(list)
    expected, held_out, held_out_drift = defaultdict(list), defaultdict(list), defaultdict(list)
    axis_errors, tilt_errors = defaultdict(list), defaultdict(list)
    z_scores = defaultdict(list)
    errors: dict[tuple, list[float]] = defaultdict(list)
    sigmas: dict[tuple, list[float]] = defaultdict(list)
    for seed in range(seeds):
        path = dry_run(PAPER, folder, seed)
        campaign = load_campaign(path)
        for mode in MODES:
            _, report = fit_campaign(campaign, FitOptions(mode=mode), {"campaign": str(path)})
            for serial, dut in report.items():
                r = dut["channels"]["accel"]  # `rig fit --json`: figures per channel
                ratios[mode].append(r["rmse_after_mg"] / r["noise_floor_mg"])
                drifts[mode].append(max(r["drift_after_mg"]))
                expected[mode].append(r["rmse_after_mg"] / r["expected_fit_rmse_mg"])
                verification = r["verification"]
                held_out[mode].append(verification["rmse_mg"] / r["noise_floor_mg"])
                held_out_drift[mode].append(max(verification["drift_mg"]))
                axis_errors[mode].append(verification["max_axis_error_mg"])
                tilt_errors[mode].append(verification["max_tilt_error_deg"])
                for record in r["truth_error"]:
                    key = (mode, serial, record["parameter"], record["setpoint_c"])
                    errors[key].append(record["error"])
                    sigmas[key].append(record["sigma"])
                    z_scores[mode].append(record["z"])
    print(f"accuracy over {seeds} dry runs of the paper campaign × 4 DUTs (11 setpoints × 24 poses, 14 × 12 "
          "verification poses, 125 Hz, 200 samples)")
    for mode in MODES:
        z = np.array(z_scores[mode])
        print(f"  {mode:9s} verification |g| RMSE / noise_floor: median {np.median(held_out[mode]):.3f}, max "
              f"{max(held_out[mode]):.3f} (target ≤ 1.2); verification drift: max {max(held_out_drift[mode]) * 1e3:.1f} µg "
              f"(target ≤ 100 µg); largest axis error {max(axis_errors[mode]):.4f} mg, tilt error "
              f"{max(tilt_errors[mode]):.4f}°")
        print(f"  {mode:9s} in-sample rmse_after / expected_fit_rmse: median {np.median(expected[mode]):.3f}, max "
              f"{max(expected[mode]):.3f}; rmse_after / noise_floor: median {np.median(ratios[mode]):.3f}, max "
              f"{max(ratios[mode]):.3f}; in-sample drift after: max {max(drifts[mode]) * 1e3:.1f} µg")
        print(f"  {mode:9s} truth within 3σ: {np.mean(np.abs(z) < 3) * 100:.2f} % of {z.size} "
              f"(Gaussian: 99.73 %), RMS z {np.sqrt(np.mean(z ** 2)):.3f}, max |z| {np.abs(z).max():.2f}")
        # Monte Carlo: the scatter of each estimate's error over the seeds against its quoted 1σ. One
        # (sensor, setpoint) from `seeds` samples is itself uncertain by ~1/√(2(seeds−1)), so pool them
        # per parameter: RMS quoted σ over RMS scatter.
        keys = [k for k in errors if k[0] == mode]
        names = list(dict.fromkeys(k[2] for k in keys))
        pooled = {}
        for name in names:
            group = [k for k in keys if k[2] == name]
            scatter = np.sqrt(np.mean([np.var(errors[k], ddof=1) for k in group]))
            quoted = np.sqrt(np.mean([np.mean(np.square(sigmas[k])) for k in group]))
            pooled[name] = quoted / scatter
        worst = max(pooled, key=lambda n: abs(np.log(pooled[n])))
        print(f"  {mode:9s} quoted 1σ / Monte Carlo scatter, pooled per parameter over 4 DUTs × 11 setpoints × "
              f"{seeds} runs: {min(pooled.values()):.2f} … {max(pooled.values()):.2f} (furthest from 1: {worst}; "
              f"target ≤ 2)")


def speed(folder: Path) -> None:
    path = dry_run(PAPER, folder, 0)
    for mode in MODES:
        poses = accelerometer_poses(load_campaign(path), "ADX355-A001")
        start = time.perf_counter()
        for _ in range(5):
            fit_vector(poses, FitOptions(mode=mode), ACCELERATION)
        one = (time.perf_counter() - start) / 5
        start = time.perf_counter()
        fit_campaign(load_campaign(path), FitOptions(mode=mode), {"campaign": str(path)})
        four = time.perf_counter() - start
        print(f"  {mode:9s} fit time: one sensor {one * 1e3:.0f} ms (11 LM fits + 12 polynomials + metrics), "
              f"4-sensor campaign {four * 1e3:.0f} ms (incl. reading it from its journal)")


def with_effects(folder: Path, hysteresis_mg: float, nonlinearity_mg_per_g2: float) -> None:
    procedure = yaml.safe_load(PAPER.read_text())
    procedure["rig"] = str(REPO / "configs" / "sim.yaml")
    procedure["simulation"] = {"hysteresis_mg": hysteresis_mg, "nonlinearity_mg_per_g2": nonlinearity_mg_per_g2}
    path = folder / "effects.yaml"
    path.write_text(yaml.safe_dump(procedure))
    campaign = dry_run(path, folder, 0)
    for mode in MODES:
        _, report = fit_campaign(load_campaign(campaign), FitOptions(mode=mode), {"campaign": str(campaign)})
        accel = [dut["channels"]["accel"] for dut in report.values()]  # figures per channel
        ratio = max(r["verification"]["rmse_mg"] / r["noise_floor_mg"] for r in accel)
        drift = max(max(r["verification"]["drift_mg"]) for r in accel)
        worst = max(abs(t["z"]) for r in accel for t in r["truth_error"])
        verdicts = sum(dut["verdict"] == "PASS" for dut in report.values())
        print(f"  hysteresis {hysteresis_mg:g} mg, non-linearity {nonlinearity_mg_per_g2:g} mg/g², {mode:9s}: "
              f"verification |g| RMSE / floor max {ratio:.1f}, verification drift max {drift * 1e3:.0f} µg, "
              f"max |z| {worst:.0f}; {verdicts} of {len(report)} PASS")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    args = parser.parse_args()
    silence_campaign_log()
    with tempfile.TemporaryDirectory() as folder:
        accuracy(args.seeds, Path(folder))
        print("speed")
        speed(Path(folder))
        print("unmodelled effects switched on (seed 0)")
        for hysteresis, nonlinearity in ((1.0, 0.0), (0.0, 0.5), (1.0, 0.5)):
            with_effects(Path(folder), hysteresis, nonlinearity)


if __name__ == "__main__":
    main()
