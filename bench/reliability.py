"""Reliability trials of unattended campaigns, as processes, the way a lab runs them. Usage:

    python bench/reliability.py syscalls --points 220   # kill -9 at chosen write system calls of rig run, fit, resume
    python bench/reliability.py crash --trials 50       # kill -9 at a random moment of the paper dry run
    python bench/reliability.py diskfull                # the disk fills up at 14 moments and sizes (needs root)
    python bench/reliability.py concurrent --trials 8   # --overwrite, resume, fit, repair against a running campaign
    python bench/reliability.py signals --trials 20     # SIGINT / SIGTERM at a random moment
    python bench/reliability.py faults --trials 2       # injected instrument faults, transient and persistent
    python bench/reliability.py faults-sweep --json     # every transient fault kind alone at 1 %, 2 %, 5 %

Every trial runs `rig run procedures/paper-24pos-thermal.yaml --dry-run` (11 setpoints × 24 poses × 4 DUTs)
and judges what is left the way a careful lab would:

- After a kill: `rig status` answers; the poses stored at the kill (read from what is on disk) are noted;
  `rig resume` (or `rig run --resume` when the kill came before the campaign existed) must exit 0 with
  every pose of the plan stored once, the campaign file as current as its journal, a calibration whose
  |g| RMSE is within 1.2 × the noise floor, and every pose stored before the kill byte for byte the same.
  `syscalls` kills at chosen write system calls (`pwrite64`, `fdatasync`, `fsync`, `rename`, spread evenly
  over an uninterrupted run's calls, fit stage included) with strace's syscall injection; it also kills
  `rig fit` at each of its writes (the campaign must be unchanged, the calibration absent or whole) and
  `rig resume` at writes spread over a resume.
- A full disk: a small tmpfs, filled by another file as soon as the campaign exists, leaving a chosen
  amount free. The run must exit 1 with "no space left on …", the safe state recorded, every stored pose
  readable; once the filler is removed `rig resume` must complete as above.
- Concurrent commands against a running campaign must be refused with one line naming its process, and
  change nothing: the running campaign's journal records, log and final result are as if alone.
- A fault sweep (`faults-sweep`) runs the paper campaign on configs/sim-lossy.yaml once per transient fault
  kind, rate and fault seed (`--fault-seeds`, default 0: what `rig run --faults rate=…` draws), that kind
  alone; a run that aborts is resumed with the same faults (`--resumes` times at most). It passes when the
  campaign ends `done` with every planned pose stored exactly once, counted in the journal's pose records
  and in the campaign file's rows, not as a reader deduplicates them.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import typing
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path

import h5py
from quiet import throwaway_registry  # bench/quiet.py, beside this script

from accelcal_rig.config.rig import FaultInjection
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.journal import Record, read_journal
from accelcal_rig.store.paths import journal_path, log_path
from accelcal_rig.store.read import file_currency, load_campaign

REPO = Path(__file__).resolve().parent.parent
PAPER = REPO / "procedures" / "paper-24pos-thermal.yaml"
LOSSY_RIG = REPO / "configs" / "sim-lossy.yaml"
RIG = str(Path(sys.executable).parent / "rig")
WRITE_CALLS = ("pwrite64", "fdatasync", "fsync", "rename")


# ---------------------------------------------------------------------- judging a campaign
def stored_poses(campaign: Path) -> dict[str, bytes]:
    """Every stored pose, by step key, as the bytes of all its numbers (empty when there is no campaign)."""
    try:
        loaded = load_campaign(campaign)
    except ConfigError:
        return {}
    return {p.step_key: b"".join([p.commanded_angles_deg.tobytes(), p.measured_angles_deg.tobytes(),
                                  repr((p.setpoint_c, p.pose_number, p.t_start_s, p.t_end_s,
                                        p.chamber_temperature_c)).encode()]
                                 + [_channels_bytes(d) + repr((d.temperature_c, d.temperature_in_band)).encode()
                                    for d in p.duts])
            for p in loaded.poses}


def _channels_bytes(dut) -> bytes:  # noqa: ANN001 (a DutPoseRecord)
    """A DUT's pose record's channels (codes, means, standard errors, references) as bytes."""
    return b"".join(c.raw_codes.tobytes() + c.mean.tobytes() + c.stderr.tobytes() + c.reference.tobytes()
                    for c in dut.channels.values())


def judge_complete(campaign: Path, before: dict[str, bytes], rmse_limit: float = 1.2) -> tuple[bool, str]:
    """Whether the campaign is complete, consistent and kept every pose of `before` unchanged."""
    try:
        loaded = load_campaign(campaign)
    except ConfigError as exc:
        return False, f"unreadable: {exc}"
    problems = loaded.integrity_problems()
    after = stored_poses(campaign)
    changed = [k for k, v in before.items() if after.get(k) != v]
    currency = file_currency(campaign, loaded, writing=False)
    calibration = campaign.with_suffix(".calibration.yaml")
    try:
        metrics = load_calibration(calibration).of_quantity("acceleration")
        worst = max(s.metrics["rmse_after_mg"] / s.metrics["noise_floor_mg"] for s in metrics.values())
    except (ConfigError, KeyError, ZeroDivisionError) as exc:
        return False, f"calibration: {exc}"
    ok = (loaded.state == "done" and len(loaded.poses) == loaded.poses_planned and not problems and not changed
          and currency == "current" and worst <= rmse_limit)
    return ok, (f"{len(loaded.poses)}/{loaded.poses_planned} poses, {len(before)} kept"
                f"{' CHANGED ' + ', '.join(changed[:3]) if changed else ''}, file {currency}, rmse/floor {worst:.2f}"
                f"{'; ' + '; '.join(problems) if problems else ''}")


def safe_state_recorded(loaded: Campaign) -> bool:
    """The last safe state in the event log (its actions are recorded one after another) set the chamber to
    23 °C, stopped the table and put 4 sensors in standby."""
    kinds = [e.kind for e in loaded.events]
    end = len(kinds) - kinds[::-1].index("safe") if "safe" in kinds else 0
    start = end
    while start > 0 and kinds[start - 1] == "safe":
        start -= 1
    safe = [e.message for e in loaded.events[start:end]]
    return (any("to 23 °C" in m for m in safe) and any("turntable" in m and "stop" in m for m in safe)
            and sum("standby" in m for m in safe) == 4)


def digests(*paths: Path) -> list[str]:
    return [hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "-" for p in paths]


def rig(*args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([RIG, *args], capture_output=True, text=True, timeout=timeout)


def one_line(result: subprocess.CompletedProcess) -> bool:
    lines = [line for line in result.stderr.strip().splitlines() if not line.startswith("rig: warning")]
    return "Traceback" not in result.stderr and (result.returncode == 0 or len(lines) == 1)


def clean(campaign: Path) -> None:
    for path in campaign.parent.glob(campaign.name + "*"):
        path.unlink()
    campaign.with_suffix(".calibration.yaml").unlink(missing_ok=True)


def finish_after_kill(campaign: Path, procedure: Path = PAPER) -> tuple[bool, str, dict[str, float]]:
    """After a kill: status answers, resume completes, what was stored is unchanged."""
    figures: dict[str, float] = {}
    status = rig("status", str(campaign), "--json")
    if not one_line(status):
        return False, f"status: {status.stderr.strip()[-200:]}", figures
    before = stored_poses(campaign)
    figures["stored_at_kill"] = len(before)
    start = time.perf_counter()
    if status.returncode == 0:
        resumed = rig("resume", str(campaign), "-q")
    else:  # killed before the campaign existed: start it again
        resumed = rig("run", str(procedure), "--dry-run", "-o", str(campaign), "--resume", "-q")
    figures["resume_wall_s"] = time.perf_counter() - start
    if resumed.returncode != 0:
        return False, f"resume exit {resumed.returncode}: {resumed.stderr.strip()[-300:]}", figures
    ok, note = judge_complete(campaign, before)
    return ok, note, figures


# ---------------------------------------------------------------------- kill -9 at chosen write calls
def count_write_calls(argv: list[str]) -> dict[str, int]:
    """How many of each write call an uninterrupted command makes."""
    with tempfile.NamedTemporaryFile("r", suffix=".strace") as counts:
        subprocess.run(["strace", "-f", "-c", "-o", counts.name, "-e",
                        f"trace={','.join(WRITE_CALLS)}", *argv], capture_output=True, check=True)
        table = counts.read()
    return {name: int(m.group(1)) for name in WRITE_CALLS
            if (m := re.search(rf"^\s*[\d.]+\s+[\d.]+\s+\d+\s+(\d+)\s+(?:\d+\s+)?{name}$", table, re.M))}


def killed_at(argv: list[str], call: str, when: int) -> subprocess.CompletedProcess:
    """Run `argv` and kill it (SIGKILL, as strace delivers it) when it enters its `when`-th `call`."""
    return subprocess.run(["strace", "-f", "-o", "/dev/null", "-e", f"trace={call}", "-e",
                           f"inject={call}:signal=SIGKILL:when={when}", *argv], capture_output=True, text=True,
                          timeout=600)


def spread(counts: dict[str, int], points: int) -> list[tuple[str, int]]:
    """`points` (call, index) pairs spread evenly over all the calls, in the order of `WRITE_CALLS`."""
    every = [(name, k) for name in WRITE_CALLS for k in range(1, counts.get(name, 0) + 1)]
    if points >= len(every):
        return every
    return [every[round(i * (len(every) - 1) / (points - 1))] for i in range(points)]


def syscall_trials(folder: Path, points: int, resume_points: int) -> tuple[int, int]:
    if shutil.which("strace") is None:
        sys.exit("syscalls: needs strace (apt-get install strace)")
    campaign = folder / "crash.h5"
    run = [RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"]
    clean(campaign)
    counts = count_write_calls(run)
    print(f"uninterrupted rig run: {counts} write calls", flush=True)
    passed = total = 0
    for call, when in spread(counts, points):
        clean(campaign)
        killed = killed_at(run, call, when)
        ok, note, figures = finish_after_kill(campaign)
        if killed.returncode == 0:  # this run made fewer such calls than the counted one (they vary by a few)
            print(f"run    {call:9s} #{when:4d}: not reached (the run ended first, exit 0; not counted); {note}",
                  flush=True)
            continue
        passed, total = passed + ok, total + 1
        print(f"run    {call:9s} #{when:4d}: {'pass' if ok else 'FAIL'}  {int(figures.get('stored_at_kill', 0)):3d} "
              f"stored at the kill; {note}", flush=True)
    # rig fit on a finished campaign, killed at each of its writes
    clean(campaign)
    subprocess.run(run, check=True, capture_output=True)
    calibration = folder / "refit.yaml"
    fit = [RIG, "fit", str(campaign), "-o", str(calibration)]
    counts = count_write_calls(fit)
    print(f"uninterrupted rig fit: {counts} write calls", flush=True)
    files = [campaign, journal_path(campaign)]
    for call, when in spread(counts, 10_000):
        calibration.unlink(missing_ok=True)
        before = digests(*files)
        killed_at(fit, call, when)
        whole = not calibration.exists() or _loads(calibration)
        again = rig("fit", str(campaign), "-o", str(calibration))
        ok = digests(*files) == before and whole and again.returncode == 0 and _loads(calibration)
        passed, total = passed + ok, total + 1
        print(f"fit    {call:9s} #{when:4d}: {'pass' if ok else 'FAIL'}  campaign unchanged "
              f"{digests(*files) == before}, calibration after the kill absent or whole {whole}", flush=True)
    # rig resume of a campaign stopped after its first setpoint, killed at writes spread over the resume
    stopped = folder / "stopped.h5"
    clean(stopped)
    _stop_after_first_setpoint(stopped)
    kept = folder / "kept"
    shutil.rmtree(kept, ignore_errors=True)
    kept.mkdir()
    for path in stopped.parent.glob(stopped.name + "*"):
        shutil.copy(path, kept / path.name)
    resume = [RIG, "resume", str(stopped), "-q"]
    counts = count_write_calls(resume)
    print(f"uninterrupted rig resume: {counts} write calls", flush=True)
    for call, when in spread(counts, resume_points):
        clean(stopped)
        for path in kept.iterdir():
            shutil.copy(path, stopped.parent / path.name)
        before = stored_poses(stopped)
        killed_at(resume, call, when)
        at_kill = stored_poses(stopped)
        kept_ok = all(at_kill.get(k) == v for k, v in before.items())
        ok, note, _ = finish_after_kill(stopped)
        ok = ok and kept_ok and judge_complete(stopped, before)[0]
        passed, total = passed + ok, total + 1
        print(f"resume {call:9s} #{when:4d}: {'pass' if ok else 'FAIL'}  {len(at_kill)} stored at the kill; {note}",
              flush=True)
    return passed, total


def _loads(calibration: Path) -> bool:
    try:
        load_calibration(calibration)
        return True
    except ConfigError:
        return False


def _stop_after_first_setpoint(campaign: Path) -> None:
    """A campaign interrupted (SIGTERM) once its first setpoint's poses are stored."""
    process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and "T-40: 24 poses stored" not in _text(log_path(campaign)):
        time.sleep(0.01)
    process.send_signal(signal.SIGTERM)
    process.wait()


def _text(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""


# ---------------------------------------------------------------------- kill -9 at a random moment
def uninterrupted_wall_s(campaign: Path) -> float:
    """The wall time of one whole paper dry run to `campaign`: the span the random moments are drawn from."""
    clean(campaign)
    start = time.perf_counter()
    subprocess.run([RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"], check=True, capture_output=True)
    return time.perf_counter() - start


def crash_trials(folder: Path, trials: int, rng: random.Random) -> tuple[int, int]:
    campaign = folder / "crash.h5"
    wall_s = uninterrupted_wall_s(campaign)
    print(f"uninterrupted run: {wall_s:.1f} s wall", flush=True)
    passed = 0
    costs = []
    for trial in range(trials):
        clean(campaign)
        at = rng.uniform(0.2, wall_s)
        process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(at)
        process.send_signal(signal.SIGKILL)
        process.wait()
        ok, note, figures = finish_after_kill(campaign)
        passed += ok
        costs.append(figures.get("resume_wall_s", 0.0))
        print(f"trial {trial:3d} at {at:5.2f} s: {'pass' if ok else 'FAIL'}  {int(figures.get('stored_at_kill', 0)):3d} "
              f"stored at the kill; {note}", flush=True)
    print(f"resume wall time: mean {sum(costs) / len(costs):.1f} s")
    return passed, trials


# ---------------------------------------------------------------------- a full disk
#: When the disk fills up (poses stored by then) and how much is left free then (bytes): from before the
#: first pose to the fit, with nothing left (the next write fails) or a little (a later one does, or the
#: check before a setpoint stops the campaign first).
#: (poses stored, bytes left) when the disk fills, over the paper campaign's 432 poses (264 calibration, then 168
#: verification): before the first, among the calibration poses, where verification begins, and at the very end
#: (the fit, the certificates and the registry rows after the last pose).
FULL_AT = [(0, 0), (0, 512 << 10), (1, 0), (30, 2 << 20), (75, 0), (100, 0), (100, 64 << 10), (150, 1 << 20),
           (200, 0), (264, 0), (264, 3 << 20), (400, 256 << 10), (431, 0), (432, 0), (432, 3 << 20)]


def diskfull_trials(folder: Path) -> tuple[int, int]:
    if os.geteuid() != 0:
        sys.exit("diskfull: needs root, to mount a small tmpfs that can really fill up")
    passed = total = 0
    for after_poses, free in FULL_AT:
        mount = folder / f"disk-{after_poses}-{free}"
        mount.mkdir()
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64m", "tmpfs", str(mount)], check=True)
        try:
            ok, note = _diskfull_trial(mount, after_poses, free)
        finally:
            subprocess.run(["umount", "-l", str(mount)], check=True)
        passed, total = passed + ok, total + 1
        print(f"full after {after_poses:3d} poses, {free / 2**20:4.2f} MiB left: {'pass' if ok else 'FAIL'}  {note}",
              flush=True)
    return passed, total


def _fill(ballast: Path, leave: int) -> None:
    """Grow `ballast` until only about `leave` bytes are free on its file system (the campaign writes meanwhile)."""
    fd = os.open(ballast, os.O_WRONLY | os.O_CREAT)
    size, chunk = 0, 8 << 20
    try:
        while True:
            stats = os.statvfs(ballast.parent)
            more = min(stats.f_bavail * stats.f_frsize - leave, chunk)
            if more <= 0:
                return
            try:
                os.posix_fallocate(fd, size, more)
                size += more
            except OSError:
                if chunk <= 4096:
                    return
                chunk //= 2
    finally:
        os.close(fd)


def _diskfull_trial(mount: Path, after_poses: int, free: int) -> tuple[bool, str]:
    campaign = mount / "c.h5"
    process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ballast = mount / "ballast"
    try:
        while process.poll() is None and not journal_path(campaign).exists():
            time.sleep(0.002)
        while process.poll() is None and _poses_stored(campaign) < after_poses:
            time.sleep(0.005)
        filled_at = _poses_stored(campaign)
        _fill(ballast, free)
        out, err = process.communicate(timeout=600)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    loaded = load_campaign(campaign)
    where = f"filled at {filled_at} poses; {len(loaded.poses)}/{loaded.poses_planned} stored, state {loaded.state}"
    status = rig("status", str(campaign), "--json")
    recorded = safe_state_recorded(loaded)
    last = err.strip().splitlines()[-1] if err.strip() else ""
    space = "no space left on" in last or "not enough space left on" in last
    if process.returncode == 0:
        said = True  # what was left was enough
    elif loaded.state == "done":  # measured whole; the fit or the last campaign file failed for space
        said = process.returncode == 1 and space
    else:
        said = process.returncode == 1 and space and loaded.state == "aborted" and recorded
    noise = "Traceback" in err or "Logging error" in err or "internal error" in err
    before = stored_poses(campaign)
    ballast.unlink()
    resumed = rig("resume", str(campaign), "-q")
    ok_after, note = judge_complete(campaign, before)
    parts = follow_up_parts(campaign)
    ok = (said and not noise and status.returncode == 0 and resumed.returncode == 0 and ok_after
          and set(parts.values()) == {"done"})
    return ok, (f"exit {process.returncode}, {where}; said {last[-100:]!r}; safe state recorded {recorded}; "
                f"resumed: {note}; follow-up {parts}")


def follow_up_parts(campaign: Path) -> dict[str, str]:
    """Each part of the campaign's follow-up (calibration, certificates, registry) → its state, as `rig status`
    reads it from the parts themselves."""
    status = rig("status", str(campaign), "--json")
    return {p["part"]: p["state"] for p in json.loads(status.stdout).get("follow_up", [])} if status.returncode == 0 else {}


def _poses_stored(campaign: Path) -> int:
    try:
        return sum(r.kind == "pose" for r in read_journal(journal_path(campaign)).records)
    except OSError:
        return 0


# ---------------------------------------------------------------------- concurrent commands
#: A campaign of some seconds (100 setpoints, six positions, 20 samples), so every command lands while it runs.
LONG_PROCEDURE = """\
name: long
rig: {rig}
setpoints_c: {{from_c: -40, to_c: 59, step_c: 1}}
soak: {{min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}}
schedule: {{kind: six-position}}
acquisition: {{samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}}
"""


def concurrent_trials(folder: Path, trials: int, rng: random.Random) -> tuple[int, int]:
    procedure = folder / "long.yaml"
    procedure.write_text(LONG_PROCEDURE.format(rig=REPO / "configs" / "sim.yaml"))
    campaign = folder / "running.h5"
    others = [["run", str(procedure), "--dry-run", "-o", str(campaign), "--overwrite", "-q"],
              ["run", str(procedure), "--dry-run", "-o", str(campaign), "--resume", "-q"],
              ["resume", str(campaign), "-q"], ["fit", str(campaign), "-o", str(folder / "other.yaml")],
              ["repair", str(campaign)]]
    passed = total = 0
    for trial in range(trials):
        clean(campaign)
        process = subprocess.Popen([RIG, "run", str(procedure), "--dry-run", "-o", str(campaign), "-q"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        while not journal_path(campaign).exists():
            time.sleep(0.005)
        time.sleep(rng.uniform(0.0, 4.0))
        refusals = []
        for argv in rng.sample(others, len(others)):
            records = [(r.offset, r.size) for r in read_journal(journal_path(campaign)).records]
            journal_before = _prefix(journal_path(campaign), records)
            log_before = log_path(campaign).read_bytes()
            other = rig(*argv)
            if process.poll() is not None:  # the campaign ended meanwhile: not a trial against a running one
                print(f"trial {trial}: the campaign ended before {argv[0]} was refused or not; not counted", flush=True)
                break
            refused = (other.returncode == 2 and one_line(other) and f"pid {process.pid} on " in other.stderr)
            unchanged = (_prefix(journal_path(campaign), records) == journal_before
                         and log_path(campaign).read_bytes().startswith(log_before))
            refusals.append((argv[0] + (" " + argv[-2] if argv[0] == "run" else ""), refused and unchanged,
                             other.stderr.strip()[-120:]))
        out, _ = process.communicate(timeout=600)
        ok_first, note = judge_complete(campaign, {}, rmse_limit=1.5)
        for name, ok, said in refusals:
            ok = ok and process.returncode == 0 and ok_first
            passed, total = passed + ok, total + 1
            print(f"trial {trial}: {name:16s} {'pass' if ok else 'FAIL'}  {said}", flush=True)
        print(f"trial {trial}: the running campaign: exit {process.returncode}; {note}", flush=True)
    return passed, total


def _prefix(journal: Path, records: list[tuple[int, int]]) -> bytes:
    data = journal.read_bytes()
    return b"".join(data[offset:offset + size] for offset, size in records)


# ---------------------------------------------------------------------- signals and faults
def _after_the_last_pose(campaign: Path, code: int, err: str) -> tuple[bool, str]:
    """A signal after the campaign was complete: exit 0 (it came once all was written), or exit 130 with one
    line saying so, and then one `rig resume` leaves every part of the follow-up done."""
    if code == 0:
        return True, "the signal came after the campaign was complete and its follow-up written"
    lines = err.strip().splitlines()
    if code != 130 or not lines or "interrupted after the campaign ended" not in lines[-1]:
        return False, f"after the campaign was complete: exit {code} {lines[-1][-80:] if lines else ''}"
    resumed = rig("resume", str(campaign), "-q")
    parts = follow_up_parts(campaign)
    ok = resumed.returncode == 0 and set(parts.values()) == {"done"}
    return ok, f"in the follow-up: exit 130, then rig resume exit {resumed.returncode}, follow-up {parts}"


def signal_trials(folder: Path, trials: int, rng: random.Random) -> tuple[int, int]:
    campaign = folder / "signal.h5"
    wall_s = uninterrupted_wall_s(campaign)
    passed = 0
    for trial in range(trials):
        clean(campaign)
        at, signum = rng.uniform(0.2, wall_s), rng.choice([signal.SIGINT, signal.SIGTERM])
        process = subprocess.Popen([RIG, "run", str(PAPER), "--dry-run", "-o", str(campaign), "-q"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(at)
        process.send_signal(signum)
        _, err = process.communicate()
        try:
            loaded = load_campaign(campaign)
        except ConfigError:
            ok = process.returncode == 130 and len(err.strip().splitlines()) == 1 and "interrupted" in err
            passed += ok
            print(f"trial {trial:3d} at {at:5.2f} s: {'pass' if ok else 'FAIL'}  before the campaign existed: exit "
                  f"{process.returncode} {err.strip()[-80:]}", flush=True)
            continue
        if loaded.state == "done":  # in its follow-up (certificates, registry): done, or finished by one resume
            ok, note = _after_the_last_pose(campaign, process.returncode, err)
        else:
            recorded = safe_state_recorded(loaded)
            ok = process.returncode == 130 and loaded.state == "aborted" and recorded and not loaded.integrity_problems()
            note = f"exit {process.returncode}, {loaded.state}, {len(loaded.poses)} poses, safe state recorded {recorded}"
        passed += ok
        print(f"trial {trial:3d} at {at:5.2f} s ({signal.Signals(signum).name}): {'pass' if ok else 'FAIL'}  {note}",
              flush=True)
    return passed, trials


def fault_trials(folder: Path, trials: int, rng: random.Random) -> tuple[int, int]:
    """The paper campaign on configs/sim-lossy.yaml (0.05 s wire timeouts, 10 tries per request)."""
    campaign = folder / "faults.h5"
    passed = total = 0
    cases = [(f"rate={rate},seed={trial}", False) for rate in (0.01, 0.05, 0.2) for trial in range(trials)]
    for _ in range(trials):
        minutes = rng.uniform(0, 600)
        cases += [(f"chamber_stall_after_min={minutes:.0f}", True), (f"turntable_stall_after_min={minutes:.0f}", True),
                  ("sensor_wrong_id=ADX355-A002", True), (f"sensor_stuck=ADX355-A003,sensor_stuck_after_min={minutes:.0f}", True)]
    for faults, persistent in cases:
        clean(campaign)
        start = time.perf_counter()
        run = rig("run", str(PAPER), "--config", str(REPO / "configs" / "sim-lossy.yaml"), "--dry-run", "-o",
                  str(campaign), "-q", "--faults", faults)
        wall = time.perf_counter() - start
        loaded = load_campaign(campaign)
        retries = sum(e.kind == "retry" for e in loaded.events)
        if persistent:
            recorded = safe_state_recorded(loaded)
            ok = run.returncode != 0 and loaded.state == "aborted" and recorded and not loaded.integrity_problems()
            note = f"aborted after {len(loaded.poses)} poses ({loaded.abort_reason[:80]}); safe state recorded {recorded}"
        else:
            ok = run.returncode == 0 and judge_complete(campaign, {})[0]
            note = f"{loaded.state}, {len(loaded.poses)}/{loaded.poses_planned} poses, {retries} retries logged"
        passed, total = passed + ok, total + 1
        print(f"{faults:48s} {'pass' if ok else 'FAIL'} in {wall:6.1f} s  {note}", flush=True)
    return passed, total


# ---------------------------------------------------------------------- a sweep of transient fault kinds
#: Every transient fault kind the simulators inject, as the rig config's `simulation.faults.kinds` lists them.
FAULT_KINDS: tuple[str, ...] = typing.get_args(typing.get_args(FaultInjection.model_fields["kinds"].annotation)[0])
SWEEP_RATES = (0.01, 0.02, 0.05)


def pose_copies(campaign: Path) -> tuple[int, int, int]:
    """(distinct poses, journal pose records beyond one per step, campaign file rows beyond one per step): a
    reader keeps the first copy of a pose stored twice, so duplicates are counted where they were written."""
    journal_keys = Counter(r.meta.get("step_key") for r in _journal_records(campaign) if r.kind == "pose")
    try:
        with h5py.File(campaign, "r") as f:
            file_keys = Counter(k.decode() if isinstance(k, bytes) else str(k) for k in f["poses/step_key"][()])
    except (OSError, KeyError):
        file_keys = Counter()
    distinct = len(set(journal_keys) | set(file_keys))
    return distinct, sum(journal_keys.values()) - len(journal_keys), sum(file_keys.values()) - len(file_keys)


def _journal_records(campaign: Path) -> list[Record]:
    try:
        return read_journal(journal_path(campaign)).records
    except OSError:
        return []


@dataclass
class SweepRow:
    """One run of the sweep: its faults, how it ended, what it stored and what it cost."""

    kind: str
    rate: float
    seed: int
    faults: str
    exits: list[int]
    abort_reasons: list[str]
    state: str
    poses_stored: int
    poses_planned: int
    duplicates: int
    retries: int
    wall_s: float
    problems: list[str]

    @property
    def completed(self) -> bool:
        return self.exits[-1] == 0 and self.state == "done"

    @property
    def ok(self) -> bool:
        """Done with every planned pose stored exactly once."""
        return self.completed and self.poses_stored == self.poses_planned and not self.duplicates and not self.problems

    def as_json(self) -> dict[str, object]:
        return {**asdict(self), "ok": self.ok, "completed": self.completed, "completed_first_run": self.exits[0] == 0,
                "resumes": len(self.exits) - 1}


def sweep_one(campaign: Path, kind: str, rate: float, seed: int, resumes: int) -> SweepRow:
    """The paper campaign on the lossy rig with `kind` alone at `rate`; resumed with the same faults while it
    aborts, `resumes` times at most. Wall seconds are the run's and its resumes' together."""
    clean(campaign)
    faults = f"rate={rate},kinds={kind},seed={seed}"
    start = time.perf_counter()
    run = rig("run", str(PAPER), "--config", str(LOSSY_RIG), "--dry-run", "-o", str(campaign), "-q",
              "--no-pdf", "--faults", faults, timeout=3600)
    exits, reasons = [run.returncode], []
    while exits[-1] != 0 and len(exits) <= resumes and campaign.exists():
        reasons.append(_last_line(run))
        run = rig("resume", str(campaign), "--config", str(LOSSY_RIG), "-q", "--no-pdf", "--faults", faults,
                  timeout=3600)
        exits.append(run.returncode)
    wall_s = time.perf_counter() - start
    if exits[-1] != 0:
        reasons.append(_last_line(run))
    try:
        loaded = load_campaign(campaign)
        state, planned, problems = loaded.state, loaded.poses_planned, loaded.integrity_problems()
        retries = sum(e.kind == "retry" for e in loaded.events)
    except ConfigError as exc:
        state, planned, problems, retries = "unreadable", 0, [str(exc)], 0
    stored, journal_duplicates, file_duplicates = pose_copies(campaign)
    return SweepRow(kind, rate, seed, faults, exits, reasons, state, stored, planned,
                    journal_duplicates + file_duplicates, retries, round(wall_s, 1), problems[:3])


def _last_line(run: subprocess.CompletedProcess) -> str:
    lines = run.stderr.strip().splitlines()
    return lines[-1][-200:] if lines else ""


def fault_sweep(folder: Path, kinds: list[str], rates: list[float], seeds: list[int], resumes: int,
                rows: list[SweepRow]) -> tuple[int, int]:
    """Every kind alone at every rate with every fault seed; each row is printed as it ends and kept in `rows`."""
    campaign = folder / "sweep.h5"
    print(f"{'kind':10s} {'rate':>5s} {'seed':>4s}  {'ok':4s} {'first run':9s} {'resumes':>7s} {'poses':>9s} "
          f"{'dupl.':>5s} {'retries':>7s} {'wall s':>7s}", flush=True)
    for kind, rate, seed in itertools.product(kinds, rates, seeds):
        row = sweep_one(campaign, kind, rate, seed, resumes)
        rows.append(row)
        print(f"{kind:10s} {rate:5.0%} {seed:4d}  {'pass' if row.ok else 'FAIL':4s} "
              f"{'done' if row.exits[0] == 0 else 'aborted':9s} {len(row.exits) - 1:7d} "
              f"{row.poses_stored:>4}/{row.poses_planned:<4} {row.duplicates:5d} {row.retries:7d} "
              f"{row.wall_s:7.1f}" + "".join(f"\n    {r}" for r in row.abort_reasons), flush=True)
    return sum(row.ok for row in rows), len(rows)


def main() -> None:
    throwaway_registry()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=["syscalls", "crash", "diskfull", "concurrent", "signals", "faults",
                                         "faults-sweep"])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--points", type=int, default=220, help="syscalls: kill points over rig run")
    parser.add_argument("--resume-points", type=int, default=40, help="syscalls: kill points over rig resume")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", action="store_true", help="end with one JSON line of the totals (faults-sweep: "
                        "and every row)")
    parser.add_argument("--kinds", default=",".join(FAULT_KINDS), help="faults-sweep: the transient kinds, "
                        "comma-separated (default: every one)")
    parser.add_argument("--rates", default=",".join(f"{r:g}" for r in SWEEP_RATES),
                        help="faults-sweep: the rates, comma-separated")
    parser.add_argument("--fault-seeds", default="0", help="faults-sweep: the fault injection's seeds, "
                        "comma-separated (default 0, as rig run draws them unless told)")
    parser.add_argument("--resumes", type=int, default=2, help="faults-sweep: resumes of a run that aborted")
    args = parser.parse_args()
    kinds = [k for k in args.kinds.split(",") if k]
    if unknown := sorted(set(kinds) - set(FAULT_KINDS)):
        parser.error(f"--kinds: {', '.join(unknown)} not among {', '.join(FAULT_KINDS)}")
    rows: list[SweepRow] = []
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        passed, total = {
            "syscalls": lambda: syscall_trials(folder, args.points, args.resume_points),
            "crash": lambda: crash_trials(folder, args.trials, rng),
            "diskfull": lambda: diskfull_trials(folder),
            "concurrent": lambda: concurrent_trials(folder, args.trials, rng),
            "signals": lambda: signal_trials(folder, args.trials, rng),
            "faults": lambda: fault_trials(folder, args.trials, rng),
            "faults-sweep": lambda: fault_sweep(folder, kinds, [float(r) for r in args.rates.split(",") if r],
                                                [int(n) for n in args.fault_seeds.split(",") if n], args.resumes,
                                                rows),
        }[args.kind]()
    print(f"{args.kind}: {passed}/{total} trials passed")
    if args.json:
        print(json.dumps({"trials": args.kind, "passed": passed, "total": total, **({"rows": [r.as_json() for r in rows]} if rows else {})}))
    sys.exit(0 if passed == total else 1)


if __name__ == "__main__":
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    main()
