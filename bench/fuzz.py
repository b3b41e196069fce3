"""Hostile inputs, each run as a process with its time and memory measured. Usage:

    python bench/fuzz.py configs --cases 600       # mutated procedure and rig files through `rig plan`
    python bench/fuzz.py campaigns --cases 132     # damaged campaigns through every command that reads them
    python bench/fuzz.py recordings --cases 300    # mutated CSV recordings and options through `rig fit-recording`
    python bench/fuzz.py exports --cases 150       # mutated calibration files through `rig export`

The generators are tests/fuzz/*.py (the test suite runs a sample of each in-process). A run passes when
the command exits 0 with nothing on stderr but warnings, or exits 1 or 2 with one line; never a
traceback or "internal error", never more than 10 s or 1 GB; and a command that only reads (status,
fit, report, analyze, fit-recording, export) leaves the campaign's files byte for byte as they were.
`rig resume` and `rig repair` may mend a campaign: when they exit 0 it must then read as complete.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from quiet import silence_campaign_log  # noqa: E402  bench/quiet.py, beside this script

from tests.fuzz.campaigns import CALIBRATION, CAMPAIGN, JOURNAL, damaged_case, make_source  # noqa: E402
from tests.fuzz.configs import config_case, mutate  # noqa: E402
from tests.fuzz.recordings import clean_recording, recording_case  # noqa: E402

RIG = str(Path(sys.executable).parent / "rig")
LIMIT_S = 10.0
LIMIT_BYTES = 1 << 30


@dataclass(frozen=True)
class Outcome:
    code: int | None          # None: killed at the time limit
    stderr: str
    wall_s: float
    max_rss_bytes: int

    def verdict(self) -> str:
        """Empty when the run behaved, else what was wrong."""
        if self.code is None:
            return f"no answer within {LIMIT_S:g} s"
        lines = [line for line in self.stderr.strip().splitlines() if not line.startswith("rig: warning")]
        if "Traceback" in self.stderr or "internal error" in self.stderr:
            return "traceback or internal error: " + self.stderr.strip()[-200:]
        if self.code not in (0, 1, 2):
            return f"exit {self.code}"
        if self.code != 0 and len(lines) != 1:
            return f"{len(lines)} lines: " + " | ".join(lines)[:200]
        if self.max_rss_bytes > LIMIT_BYTES:
            return f"{self.max_rss_bytes / 2**20:.0f} MB"
        return ""


def run(argv: list[str], cwd: Path | None = None) -> Outcome:
    """`rig argv…` as a process: exit code, stderr, wall time, peak memory (killed after LIMIT_S)."""
    with tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        process = subprocess.Popen([RIG, *argv], stdout=subprocess.DEVNULL, stderr=err, cwd=cwd,
                                   stdin=subprocess.DEVNULL)
        code: int | None = None
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                code = os.waitstatus_to_exitcode(status)
                break
            if time.perf_counter() - start > LIMIT_S:
                process.send_signal(signal.SIGKILL)
                _, _, usage = os.wait4(process.pid, 0)
                break
            time.sleep(0.005)
        process.returncode = code if code is not None else -9
        wall = time.perf_counter() - start
        err.seek(0)
        return Outcome(code, err.read(), wall, usage.ru_maxrss * 1024)


def report(kind: str, results: list[tuple[str, Outcome, str]]) -> int:
    failed = [(what, o, why) for what, o, why in results if why]
    walls = sorted(o.wall_s for _, o, _ in results)
    rss = max(o.max_rss_bytes for _, o, _ in results)
    codes = {c: sum(o.code == c for _, o, _ in results) for c in sorted({o.code for _, o, _ in results}, key=str)}
    for what, _, why in failed:
        print(f"FAIL {what}: {why}", flush=True)
    print(f"{kind}: {len(results) - len(failed)}/{len(results)} runs passed; exit codes {codes}; wall median "
          f"{walls[len(walls) // 2]:.2f} s, max {walls[-1]:.2f} s; peak memory {rss / 2**20:.0f} MB")
    print(json.dumps({"inputs": kind, "runs": len(results), "passed": len(results) - len(failed),
                      "max_wall_s": round(walls[-1], 2), "max_rss_mb": round(rss / 2**20)}))
    return len(failed)


def configs(folder: Path, numbers: list[int]) -> int:
    results = []
    for number in numbers:
        case = config_case(number)
        outcome = run(["plan", str(case.write(folder / f"case{number}"))])
        named = "procedure.yaml" in outcome.stderr or "rig.yaml" in outcome.stderr
        why = outcome.verdict() or ("" if outcome.code == 0 or named else "the error names neither file")
        results.append((f"config {number} ({case.mutated} {case.seed}: {case.mutation[:60]})", outcome, why))
        if number % 50 == 49:
            print(f"{number + 1} configs run", flush=True)
    return report("configs", results)


def _digests(folder: Path) -> list[str]:
    return [hashlib.sha256((folder / n).read_bytes()).hexdigest() if (folder / n).is_file() else "-"
            for n in (CAMPAIGN, JOURNAL)]


def campaigns(folder: Path, numbers: list[int]) -> int:
    from accelcal_rig.errors import ConfigError
    from accelcal_rig.store.read import campaign_status

    source = make_source(folder / "source", REPO / "configs" / "sim.yaml")
    readers = {
        "status": lambda f: ["status", str(f / CAMPAIGN), "--json"],
        "fit": lambda f: ["fit", str(f / CAMPAIGN), "-o", str(f / "out.yaml")],
        "report": lambda f: ["report", str(f / CAMPAIGN), "-o", str(f / "report")],
        "positions": lambda f: ["analyze", "positions", str(f / CAMPAIGN), "--sizes", "8,12", "--subsets", "2"],
        "tilt": lambda f: ["analyze", "tilt", str(f / CAMPAIGN), "--calibration", str(f / CALIBRATION)],
        "cooldown": lambda f: ["analyze", "cooldown", str(f / CAMPAIGN), "--calibration", str(f / CALIBRATION)],
        "fit-recording": lambda f: ["fit-recording", str(f / CAMPAIGN), "-o", str(f / "recording.yaml")],
    }
    writers = {"resume": lambda f: ["resume", str(f / CAMPAIGN), "-q"], "repair": lambda f: ["repair", str(f / CAMPAIGN)]}
    results = []
    for number in numbers:
        case = folder / f"case{number}"
        what = damaged_case(number, source, case)
        before = _digests(case)
        for name, argv in readers.items():
            outcome = run(argv(case))
            why = outcome.verdict() or ("" if _digests(case) == before else "changed what it read")
            results.append((f"campaign {number} ({what[:60]}) {name}", outcome, why))
        for name, argv in writers.items():
            copy = folder / f"case{number}-{name}"
            damaged_case(number, source, copy)
            outcome = run(argv(copy))
            why = outcome.verdict()
            if not why and outcome.code == 0 and name == "resume":
                try:
                    status = campaign_status(copy / CAMPAIGN)
                    complete = status["state"] == "done" and status["poses_done"] == status["poses_total"]
                    why = "" if complete and status["campaign_file"] == "current" else f"after it: {status}"
                except ConfigError as exc:
                    why = f"unreadable after it: {exc}"
            results.append((f"campaign {number} ({what[:60]}) {name}", outcome, why))
            shutil.rmtree(copy, ignore_errors=True)
        shutil.rmtree(case, ignore_errors=True)
        if number % 10 == 9:
            print(f"{number + 1} campaigns run", flush=True)
    return report("campaigns", results)


def recordings(folder: Path, numbers: list[int]) -> int:
    clean = clean_recording()
    results = []
    for number in numbers:
        case = recording_case(number, clean)
        outcome = run(case.argv(folder / f"case{number}"))
        written = (folder / f"case{number}" / "out.yaml").is_file()
        why = outcome.verdict() or ("" if (outcome.code == 0) == written else "calibration written on failure or missing")
        results.append((f"recording {number} ({case.mutation[:60]})", outcome, why))
    return report("recordings", results)


def exports(folder: Path, numbers: list[int]) -> int:
    source = make_source(folder / "source", REPO / "configs" / "sim.yaml")
    text = (source / CALIBRATION).read_text()
    results = []
    for number in numbers:
        data, description = mutate(text, random.Random(number))
        path = folder / f"cal{number}.yaml"
        path.write_bytes(data)
        fmt = ("json", "csv", "c-header")[number % 3]
        outcome = run(["export", str(path), "--format", fmt, "-o", str(folder / f"out{number}")])
        results.append((f"calibration {number} ({description[:60]}) {fmt}", outcome, outcome.verdict()))
    return report("exports", results)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", choices=["configs", "campaigns", "recordings", "exports"])
    parser.add_argument("--cases", type=int)
    parser.add_argument("--only", metavar="N,M,…", help="these case numbers only (each case is made from its number: "
                        "a failure is re-run on its own)")
    args = parser.parse_args()
    cases = args.cases or {"configs": 600, "campaigns": 132, "recordings": 300, "exports": 150}[args.inputs]
    numbers = [int(n) for n in args.only.split(",")] if args.only else list(range(cases))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    silence_campaign_log()  # the source campaigns' soak warnings are not what is judged
    with tempfile.TemporaryDirectory() as tmp:
        failures = {"configs": configs, "campaigns": campaigns, "recordings": recordings,
                    "exports": exports}[args.inputs](Path(tmp), numbers)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
