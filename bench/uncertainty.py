"""Is the stated uncertainty true? A Monte Carlo over repeated dry runs (GUM Supplement 1 style: the whole
measurement repeated with new noise, the same simulated sensors): at every verification pose, each axis's
error of the compensated output against the simulation truth, against that pose's expanded uncertainty
(k = 2). The observed coverage should be 95 % (target 93–97 %).

Default: the paper campaign on the plain simulated rig, at two sites: the shipped rig (the standard gravity,
no stated uncertainty) and one whose gravity is stated with an uncertainty (each run's simulated site drawn
from it), each run fitted in both modes.

`--honest`: each `--method`'s shipped procedure (bench/throughput.py's METHODS) on the honest rig, as
bench/throughput.py writes it (`configs/sim-honest.yaml` with `--duts` DUTs, the sensors' hysteresis and
rate effects of its SENSOR_EFFECTS, its verification poses at rest), fitted as the procedure says; the
coverage pooled over the runs and DUTs, the scatter of error/u, and where the errors outside lie: by
temperature, by the side each pose's temperature was approached from, each source's share. Usage:

    python bench/uncertainty.py [--runs 10] [--json]
    python bench/uncertainty.py --honest [--method soak,ramp,bidirectional-ramp] [--runs 10] [--first-seed 0]
                                [--duts 16] [--keep DIR] [--json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from collections import defaultdict
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np
import yaml
from quiet import silence_campaign_log, throwaway_registry  # bench/quiet.py, beside this script
from throughput import METHODS, SENSOR_EFFECTS, variant  # bench/throughput.py: the honest rig and procedures

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit import vector_model
from accelcal_rig.fit.acceleration import ACCELERATION, accelerometer_poses
from accelcal_rig.fit.budget import truth_errors
from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.fit.recorded_options import recorded_options
from accelcal_rig.fit.uncertainty import COVERAGE_FACTOR, combined
from accelcal_rig.fit.vector_model import fit_vector, with_approach
from accelcal_rig.store.content import Campaign
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


#: A move of the DUT's temperature larger than this (the chamber's overshoot and its return are about 1 °C) is
#: the side a pose's temperature was approached from, for the breakdown (the fit's own `approach` looks at
#: the last ten minutes only: an overshoot's return reads as the other side).
MOVE_C = 2.0


def approached_from(campaign: Campaign, serial: str, t_s: np.ndarray, temperature_c: np.ndarray) -> np.ndarray:
    """+1 where the DUT last came to a pose's temperature from more than MOVE_C below it, −1 from above, 0 if
    it never was that far away (its soak traces and poses in time)."""
    times = [np.asarray(s.t_s, dtype=float) for s in campaign.soaks if len(s.t_s)]
    readings = [np.asarray(s.dut_c, dtype=float)[:, (list(s.serials) or campaign.serials).index(serial)]
                for s in campaign.soaks if len(s.t_s)]
    poses = accelerometer_poses(campaign, serial)
    history_t = np.concatenate(times + [poses.t_s])
    history_c = np.concatenate(readings + [poses.temperature_c])
    order = np.argsort(history_t, kind="stable")
    history_t, history_c = history_t[order], history_c[order]
    sides = np.zeros(len(t_s))
    for k, (t, c) in enumerate(zip(t_s, temperature_c)):
        away = np.flatnonzero((history_t < t) & (np.abs(history_c - c) > MOVE_C))
        if len(away):
            sides[k] = np.sign(c - history_c[away[-1]])
    return sides


def verification_checks(campaign: Campaign) -> list[dict[str, Any]]:
    """Each DUT fitted as its procedure says, and of its verification poses, one record per pose: its
    temperature, the direction it was approached from and its rate of change, each axis's error against
    the truth, each source of the budget and the combined standard uncertainty (mg). The fit is the
    campaign's own (fit_vector); only its truth check is recorded on its way (truth_errors, the same inputs).
    Directions: `approach` as the fit sees it (the last ten minutes), `side` the last move beyond MOVE_C."""
    options = recorded_options(campaign.attrs, "the campaign's procedure's fit")
    assert options is not None
    records: list[dict[str, Any]] = []
    real = vector_model.truth_coverage
    seen: list[tuple[Any, ...]] = []
    last: dict[str, tuple[Any, ...]] = {}
    with mock.patch.object(vector_model, "truth_coverage", lambda *args: seen.append(args) or real(*args)):
        for serial in campaign.serials:  # with_approach: each pose's direction, to sort by
            fit_vector(with_approach(campaign, accelerometer_poses(campaign, serial, options)), options, ACCELERATION)
            # A hysteresis fit checks twice: the calibration alone as applied, then the model at each check's
            # state, whose coverage is the one it reports (`truth_coverage_k2`): its last.
            last[serial] = seen[-1]
    for serial, arguments in last.items():
        checks, _, _, _, temperature_c, _, _, _ = arguments
        errors, sources = truth_errors(*arguments)
        u = combined(sources)
        sides = approached_from(campaign, serial, checks.t_s, checks.temperature_c)
        for k in range(len(errors)):
            records.append({
                "serial": serial, "setpoint_c": float(checks.setpoint_c[k]), "temperature_c": float(temperature_c[k]),
                "approach": float(checks.approach[k]), "side": float(sides[k]),
                "rate_c_per_min": float(checks.rate_c_per_min[k]),
                "error_mg": (1e3 * errors[k]).tolist(), "u_mg": (1e3 * u[k]).tolist(),
                "sources_mg": {name: (1e3 * v[k]).tolist() for name, v in sources.items()}})
    return records


def coverage_of(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Pooled over the records' axes: the share inside k·u, the scatter of error/u (1 if the budget is
    true and Gaussian), the RMS error and RMS u in mg, and each source's RMS."""
    errors = np.array([r["error_mg"] for r in records])
    u = np.array([r["u_mg"] for r in records])
    return {"coverage_k2": float(np.mean(np.abs(errors) <= COVERAGE_FACTOR * u)), "axis_errors": errors.size,
            "z_rms": float(np.sqrt(np.mean((errors / u) ** 2))), "error_rms_mg": float(np.sqrt(np.mean(errors**2))),
            "u_rms_mg": float(np.sqrt(np.mean(u**2))),
            "sources_rms_mg": {name: float(np.sqrt(np.mean(np.array([r["sources_mg"][name] for r in records]) ** 2)))
                               for name in records[0]["sources_mg"]}}


def breakdown(records: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """The coverage by verification temperature (its setpoint), by the side its temperature was approached
    from (`side`) and by the direction the fit gives it (`approach`)."""
    by: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in sorted(records, key=lambda r: r["setpoint_c"]):
        by[f"{r['setpoint_c']:g} °C"].append(r)
    for r in records:
        by[{1.0: "from below", -1.0: "from above", 0.0: "unmoved"}[r["side"]]].append(r)
    for r in records:
        by["fit: warming" if r["approach"] > 0 else "fit: cooling"].append(r)
    return {name: coverage_of(rows) for name, rows in by.items()}


def honest(methods: list[str], seeds: range, duts: int, keep: Path | None) -> dict[str, dict[str, Any]]:
    """Each method's runs on the honest rig (bench/throughput.py's variant), pooled."""
    results: dict[str, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for method in methods:
            per_run: list[float] = []
            records: list[dict[str, Any]] = []
            for seed in seeds:
                folder = keep or Path(tmp)
                folder.mkdir(parents=True, exist_ok=True)
                procedure = variant(method, duts, folder)
                output = folder / f"{method}-{seed}.h5"
                run_campaign(prepare(procedure), output, dry_run=True, seed=seed, overwrite=True)
                found = verification_checks(load_campaign(output))
                for serial in dict.fromkeys(r["serial"] for r in found):
                    per_run.append(coverage_of([r for r in found if r["serial"] == serial])["coverage_k2"])
                records += [{**r, "seed": seed} for r in found]
            results[method] = {**coverage_of(records), "runs": len(seeds), "duts": duts,
                               "per_dut_min": min(per_run), "per_dut_max": max(per_run),
                               "by": breakdown(records)}
    return results


def print_honest(results: dict[str, dict[str, Any]], seeds: range) -> None:
    print(f"coverage of the k = 2 interval on the honest rig (bench/throughput.py's, sensor effects {SENSOR_EFFECTS}), "
          f"seeds {seeds.start}…{seeds.stop - 1} (target 93–97 %; Gaussian 95.45 %)")
    for method, r in results.items():
        print(f"  {method}: {r['coverage_k2'] * 100:.2f} % of {r['axis_errors']} axis errors ({r['runs']} runs × "
              f"{r['duts']} DUTs; per DUT and run {r['per_dut_min'] * 100:.1f} … {r['per_dut_max'] * 100:.1f} %); "
              f"error/u scatter {r['z_rms']:.2f}; RMS error {r['error_rms_mg']:.4f} mg, RMS u {r['u_rms_mg']:.4f} mg")
        for name, b in r["by"].items():
            shares = ", ".join(f"{k} {v:.4f}" for k, v in b["sources_rms_mg"].items() if v > 0)
            print(f"    {name:>12}: {b['coverage_k2'] * 100:6.2f} % of {b['axis_errors']:5d}; error/u {b['z_rms']:.2f}; "
                  f"RMS error {b['error_rms_mg']:.4f} mg, u {b['u_rms_mg']:.4f} mg ({shares})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--honest", action="store_true", help="the shipped methods on bench/throughput.py's honest rig")
    parser.add_argument("--method", default=",".join(METHODS), help="with --honest, comma-separated, of: "
                        + ", ".join(METHODS))
    parser.add_argument("--first-seed", type=int, default=0, help="with --honest: the first run's seed")
    parser.add_argument("--duts", type=int, default=16, help="with --honest: the fixture's DUTs")
    parser.add_argument("--keep", type=Path, help="with --honest: keep the campaigns in this folder")
    args = parser.parse_args()
    silence_campaign_log()
    if args.honest:
        throwaway_registry()
        seeds = range(args.first_seed, args.first_seed + args.runs)
        found = honest(args.method.split(","), seeds, args.duts, args.keep)
        if args.json:
            print(json.dumps({"methods": found, "sensor_effects": SENSOR_EFFECTS, "seeds": list(seeds)}))
        else:
            print_honest(found, seeds)
        return
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
                    for r in (dut["channels"]["accel"] for dut in report.values()):  # figures per channel
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
