"""Reliability trials of unattended campaigns, as processes, the way a lab runs them. Usage:

    python bench/reliability.py crash --trials 50     # kill -9 the paper dry run at a random moment, resume
    python bench/reliability.py signals --trials 20   # SIGINT / SIGTERM at a random moment
    python bench/reliability.py faults --trials 3     # injected faults, transient and persistent

Crash trials: `rig run procedures/paper-24pos-thermal.yaml --dry-run` is killed with SIGKILL at a moment
drawn uniformly over an uninterrupted run's wall time; the file must open with h5py as the kill left
it; `rig resume` must finish the campaign with every pose of the plan stored exactly once and a fit as
good as an uninterrupted run's (|g| RMSE after calibration within 1.2 × the noise floor, the figure the
accuracy benchmark holds every fit to). Signal trials: the run must exit 130 with the file `aborted`, the
poses stored whole, and the simulators' last chamber setpoint the safe one, each sensor in standby and
the turntable stopped, as the file's event log records. Fault trials: with 1 %, 5 % and 20 % of all
replies spoiled (dropped, late, corrupted, a line dead for 2 s of campaign time) the campaign must complete with every
pose stored once; with a persistent fault (chamber or turntable stall at a random time, a wrong part ID,
a DUT whose data freeze at a random time) it must end `aborted` with the safe state recorded. Fault
trials use a copy of the simulated rig with 0.05 s wire timeouts and 10 tries per request (a lab with a
link this bad would configure the same), so that a dropped reply costs 0.05 s of wall time.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
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
    t_first_pose = next(t for t, m in after if re.fullmatch(r"\S+/pose\d+ stored", m))
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
        ok = process.returncode == 130 and len(err.strip().splitlines()) == 1 and "interrupted" in err
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


def lossy_rig(folder: Path) -> Path:
    """The paper procedure on a copy of the simulated rig with short timeouts and more retries."""
    rig = (REPO / "configs" / "sim.yaml").read_text()
    for section in ("chamber:\n", "turntable:\n"):
        rig = rig.replace(section, section + "  timeout_s: 0.05\n", 1)
    for n in range(1, 5):
        rig = rig.replace(f"name: dut{n}", f"name: dut{n}, timeout_s: 0.05", 1)
    (folder / "sim.yaml").write_text(rig + "retry: {attempts: 10}\n")
    procedure = folder / "paper.yaml"
    procedure.write_text(PAPER.read_text().replace("rig: ../configs/sim.yaml", "rig: sim.yaml"))
    return procedure


def fault_trial(procedure: Path, faults: str, persistent: bool) -> tuple[bool, str, float]:
    output = procedure.parent / "faults.h5"
    for stale in (output, output.with_suffix(".h5.log")):
        stale.unlink(missing_ok=True)
    start = time.perf_counter()
    run = subprocess.run([RIG, "run", str(procedure), "--dry-run", "-o", str(output), "-q", "--faults", faults],
                         capture_output=True, text=True)
    wall = time.perf_counter() - start
    with h5py.File(output, "r") as f:
        state, problems = str(f.attrs["state"]), integrity_problems(f)
        stored, planned = f["poses/step_key"].shape[0], int((f["plan/kind"][:] == b"pose").sum())
        kinds = [k.decode() for k in f["events/kind"][:]]
        messages = [m.decode() for m in f["events/message"][:]]
        reason = str(f.attrs["abort_reason"])
    retries = kinds.count("retry")
    if persistent:
        safe = messages[-8:]
        recorded = (any("to 23 °C" in m for m in safe) and any("turntable" in m and "stop" in m for m in safe)
                    and sum("standby" in m for m in safe) == 4)
        ok = run.returncode != 0 and state == "aborted" and recorded and not problems
        return ok, f"aborted after {stored} poses ({reason[:90]}); safe state recorded: {recorded}", wall
    ok = run.returncode == 0 and state == "done" and stored == planned and not problems
    return ok, f"{state}, {stored}/{planned} poses, {retries} retries logged{'; ' + run.stderr[-120:] if not ok else ''}", wall


def fault_trials(folder: Path, trials: int, rng: random.Random) -> tuple[int, int]:
    procedure = lossy_rig(folder)
    passed = total = 0
    for rate in (0.01, 0.05, 0.2):
        for trial in range(trials):
            ok, note, wall = fault_trial(procedure, f"rate={rate},seed={trial}", persistent=False)
            passed, total = passed + ok, total + 1
            print(f"transient {rate:4.0%} seed {trial}: {'pass' if ok else 'FAIL'} in {wall:5.1f} s  {note}", flush=True)
    for trial in range(trials):
        minutes = rng.uniform(0, 600)
        for faults in (f"chamber_stall_after_min={minutes:.0f}", f"turntable_stall_after_min={minutes:.0f}",
                       "sensor_wrong_id=ADX355-A002", f"sensor_stuck=ADX355-A003,sensor_stuck_after_min={minutes:.0f}"):
            ok, note, wall = fault_trial(procedure, faults, persistent=True)
            passed, total = passed + ok, total + 1
            print(f"persistent {faults}: {'pass' if ok else 'FAIL'} in {wall:5.1f} s  {note}", flush=True)
    return passed, total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=["crash", "signals", "faults"])
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if args.kind == "faults":
            passed, total = fault_trials(folder, args.trials, rng)
            print(f"faults: {passed}/{total} trials passed")
            sys.exit(0 if passed == total else 1)
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
