"""Reliability trials of unattended campaigns, as processes, the way a lab runs them. Usage:

    python bench/reliability.py crash --trials 50     # kill -9 the paper dry run at a random moment, resume
    python bench/reliability.py signals --trials 20   # SIGINT / SIGTERM at a random moment

Crash trials: `rig run procedures/paper-24pos-thermal.yaml --dry-run` is killed with SIGKILL at a moment
drawn uniformly over an uninterrupted run's wall time; the file must open with h5py as the kill left
it; `rig resume` must finish the campaign with every pose of the plan stored exactly once and a fit as
good as an uninterrupted run's (|g| RMSE after calibration within 1.2 × the noise floor, the figure the
accuracy benchmark holds every fit to). Signal trials: the run must exit 130 with the file `aborted`, the
poses stored whole, and the simulators' last chamber setpoint the safe one, each sensor in standby and
the turntable stopped, as the file's event log records.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

from accelcal_rig.store.read import integrity_problems

REPO = Path(__file__).resolve().parent.parent
PAPER = REPO / "procedures" / "paper-24pos-thermal.yaml"
RIG = str(Path(sys.executable).parent / "rig")


def fit_metrics(campaign: Path) -> dict[str, tuple[float, float]]:
    """Per DUT: (rmse_after_mg, noise_floor_mg) from the file's fit/ group."""
    with h5py.File(campaign, "r") as f:
        metrics = {serial: json.loads(f[f"fit/{serial}/metrics_json"][()]) for serial in f["duts"]}
    return {serial: (m["rmse_after_mg"], m["noise_floor_mg"]) for serial, m in metrics.items()}


def uninterrupted(folder: Path) -> tuple[float, dict[str, tuple[float, float]]]:
    output = folder / "reference.h5"
    start = time.perf_counter()
    subprocess.run([RIG, "run", str(PAPER), "--dry-run", "-o", str(output), "-q"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start, fit_metrics(output)


def crash_trial(folder: Path, kill_at_s: float) -> tuple[bool, str, dict[str, float]]:
    output = folder / "crash.h5"
    for stale in (output, output.with_suffix(".h5.log"), output.with_suffix(".calibration.yaml")):
        stale.unlink(missing_ok=True)
    process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(output), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(kill_at_s)
    process.send_signal(signal.SIGKILL)
    process.wait()
    figures: dict[str, float] = {}
    if not output.exists():
        return True, "killed before the file existed (nothing to resume: a new run starts over)", figures
    try:
        with h5py.File(output, "r") as f:
            figures["stored_at_kill"] = f["poses/step_key"].shape[0]
            figures["rows_ragged_at_kill"] = float(bool(integrity_problems(f)))
            state = str(f.attrs["state"])
    except OSError as exc:
        return False, f"unreadable after the kill: {exc}", figures
    if state == "done":
        return True, "killed after the campaign was complete", figures
    start = time.perf_counter()
    resumed = subprocess.run([RIG, "resume", str(output), "-q"], capture_output=True, text=True)
    figures["resume_wall_s"] = time.perf_counter() - start
    if resumed.returncode != 0:
        return False, f"resume exit {resumed.returncode}: {resumed.stderr.strip()[-200:]}", figures
    with h5py.File(output, "r") as f:
        problems = integrity_problems(f)
        stored, planned = f["poses/step_key"].shape[0], int((f["plan/kind"][:] == b"pose").sum())
        events = [(float(t), m.decode()) for t, m in zip(f["events/t_s"][:], f["events/message"][:])]
    if problems or stored != planned:
        return False, f"{stored}/{planned} poses; {'; '.join(problems)}", figures
    figures.update(resume_cost(events))
    worst = max(rmse / floor for rmse, floor in fit_metrics(output).values())
    figures["rmse_over_floor"] = worst
    if worst > 1.2:
        return False, f"fit after resume: rmse_after / noise floor {worst:.2f} > 1.2", figures
    return True, f"{int(figures['stored_at_kill'])} poses at the kill, resumed to {stored}", figures


def resume_cost(events: list[tuple[float, str]]) -> dict[str, float]:
    """Campaign-clock seconds the resumed run spent before its first ramp, in its ramp and soak, and
    between the end of that soak and the first pose stored."""
    index = next(i for i, (_, m) in enumerate(events) if "resumes after" in m)
    t_resume, after = events[index][0], events[index:]
    ramps = [t for t, m in after if "→ ramp" in m]
    if not ramps:
        return {}  # every pose was stored when the kill came: the resume only made safe and fitted
    t_ramp = ramps[0]
    t_soak_end = next(t for t, m in after if m.startswith("soak → move"))
    t_first_pose = next(t for t, m in after if m.endswith(" stored"))
    return {"before_ramp_s": t_ramp - t_resume, "ramp_and_soak_s": t_soak_end - t_ramp,
            "first_pose_after_soak_s": t_first_pose - t_soak_end}


def signal_trial(folder: Path, send_at_s: float, signum: int) -> tuple[bool, str]:
    output = folder / "signal.h5"
    for stale in (output, output.with_suffix(".h5.log")):
        stale.unlink(missing_ok=True)
    process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(output), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(send_at_s)
    process.send_signal(signum)
    _, err = process.communicate()
    if not output.exists():
        ok = process.returncode == 130 and "nothing was moved" in err
        return ok, f"before the file existed: exit {process.returncode} {err.strip()[-80:]}"
    with h5py.File(output, "r") as f:
        state = str(f.attrs["state"])
        problems = integrity_problems(f)
        safe = [m.decode() for m, k in zip(f["events/message"][:], f["events/kind"][:]) if k == b"safe"]
    if state == "done":
        return process.returncode == 0, "the signal came after the campaign was complete"
    chamber_safe = any("to 23 °C" in m for m in safe[-6:])
    standby = sum("standby" in m for m in safe[-6:]) == 4
    stopped = any("turntable" in m and "stop" in m for m in safe[-6:])
    ok = process.returncode == 130 and state == "aborted" and not problems and chamber_safe and standby and stopped
    return ok, f"exit {process.returncode}, state {state}, safe: chamber {chamber_safe} turntable {stopped} " \
               f"sensors {standby}{'; ' + '; '.join(problems) if problems else ''}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=["crash", "signals"])
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        wall_s, reference = uninterrupted(folder)
        worst_reference = max(rmse / floor for rmse, floor in reference.values())
        print(f"uninterrupted run: {wall_s:.1f} s wall, rmse_after / noise floor worst {worst_reference:.2f}")
        passed, costs = 0, []
        for trial in range(args.trials):
            at = rng.uniform(0.2, wall_s)
            if args.kind == "crash":
                ok, note, figures = crash_trial(folder, at)
                if "before_ramp_s" in figures:
                    costs.append(figures)
            else:
                ok, note = signal_trial(folder, at, rng.choice([signal.SIGINT, signal.SIGTERM]))
            passed += ok
            print(f"trial {trial:3d} at {at:5.2f} s: {'pass' if ok else 'FAIL'}  {note}", flush=True)
        print(f"{args.kind}: {passed}/{args.trials} trials passed")
        if costs:
            mean = lambda key: sum(c[key] for c in costs) / len(costs)  # noqa: E731
            print(f"resume, mean of {len(costs)}: {mean('resume_wall_s'):.1f} s wall for the resume command; "
                  f"campaign clock: {mean('before_ramp_s'):.1f} s before the first ramp, "
                  f"{mean('ramp_and_soak_s') / 60:.1f} min ramp and re-soak, "
                  f"{mean('first_pose_after_soak_s'):.1f} s from the soak to the first pose stored; "
                  f"worst rmse_after / noise floor {max(c['rmse_over_floor'] for c in costs):.2f}; "
                  f"a pose cut mid-write in {sum(c['rows_ragged_at_kill'] for c in costs):.0f} trials")
    sys.exit(0 if passed == args.trials else 1)


if __name__ == "__main__":
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    main()
