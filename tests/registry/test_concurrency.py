"""Two rigs finishing at once: two processes open a registry nobody has created yet and each records 100
calibrations of its own and 50 that both hold, at the same moment — every one is there, once."""

from __future__ import annotations

import pickle
import select
import subprocess
import sys
from pathlib import Path

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.entries import campaign_entries
from tests.registry.conftest import synthetic_entries

WRITER = """
import pickle, sys, time
from pathlib import Path
from accelcal_rig.registry.database import Registry
url, entries_file, go = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
entries = pickle.loads(entries_file.read_bytes())
print("ready", flush=True)
deadline = time.monotonic() + 60
while not go.exists():
    assert time.monotonic() < deadline, "never told to go"
    time.sleep(0.001)
added, already = Registry.open(url).add(entries)
print(len(added), already)
"""


def test_two_writers_at_once_lose_nothing_and_duplicate_nothing(registry_url: str, quick_campaign, tmp_path: Path) -> None:
    campaign, calibration = quick_campaign
    template = campaign_entries(campaign, calibration)[0]
    shared = synthetic_entries(template, 50, prefix="BOTH")
    go = tmp_path / "go"
    writers = []
    for rig in ("A", "B"):
        entries_file = tmp_path / f"{rig}.pickle"
        entries_file.write_bytes(pickle.dumps([*synthetic_entries(template, 100, prefix=f"RIG{rig}"), *shared]))
        writers.append(subprocess.Popen([sys.executable, "-c", WRITER, registry_url, str(entries_file), str(go)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    for writer in writers:  # both started, and waiting for the word (within a deadline: a stuck one fails)
        assert writer.stdout is not None
        assert select.select([writer.stdout], [], [], 60)[0], "a writer never said it was ready"
        assert writer.stdout.readline().strip() == "ready"
    go.touch()
    results = [writer.communicate(timeout=120) for writer in writers]
    assert all(writer.returncode == 0 for writer in writers), [err for _, err in results]
    counts = [tuple(int(n) for n in out.split()) for out, _ in results]  # what each printed after "ready"
    assert sum(added for added, _ in counts) == 250 and sum(already for _, already in counts) == 50
    registry = Registry.open(registry_url)
    assert registry.count() == 250
    assert len({r["serial"] for r in registry.calibrations()}) == 250
