"""The dashboard's page load with a lab's worth of campaigns: 20 copies of one paper-campaign dry run
(432 poses × 4 DUTs each) in the watched folder, `rig serve` as a user starts it, and the front page, its
JSON and one campaign's page fetched over HTTP on the wall clock — the first load (every campaign read)
and the loads after (each read again only when it changes). Usage:

    python bench/dashboard.py [--campaigns 20] [--loads 10] [--json]
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare

REPO = Path(__file__).resolve().parent.parent
RIG = str(Path(sys.executable).parent / "rig")


def fetch_s(url: str) -> float:
    start = time.perf_counter()
    with urllib.request.urlopen(url, timeout=120) as response:
        response.read()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--campaigns", type=int, default=20)
    parser.add_argument("--loads", type=int, default=10)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    silence_campaign_log()
    with tempfile.TemporaryDirectory() as folder_name:
        folder = Path(folder_name)
        first = folder / "paper-00.h5"
        run_campaign(prepare(REPO / "procedures" / "paper-24pos-thermal.yaml"), first, dry_run=True, seed=0,
                     overwrite=False)
        for k in range(1, args.campaigns):
            for source in folder.glob("paper-00.h5*"):
                if source.is_file():
                    shutil.copy(source, folder / source.name.replace("paper-00", f"paper-{k:02d}"))
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        server = subprocess.Popen([RIG, "serve", "--campaigns", str(folder), "--port", str(port)],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            line = server.stdout.readline()  # type: ignore[union-attr]
            base = re.search(r"(http://\S+)", line).group(1).rstrip("/")  # type: ignore[union-attr]
            figures = {"first_front_page_s": fetch_s(f"{base}/")}
            figures["front_page_s"] = statistics.median(fetch_s(f"{base}/") for _ in range(args.loads))
            figures["campaigns_json_s"] = statistics.median(fetch_s(f"{base}/api/campaigns") for _ in range(args.loads))
            figures["campaign_page_s"] = statistics.median(fetch_s(f"{base}/campaigns/paper-07.h5")
                                                           for _ in range(args.loads))
        finally:
            server.terminate()
            server.wait(timeout=20)
    if args.json:
        print(json.dumps({"campaigns": args.campaigns, **figures}))
        return
    print(f"dashboard with {args.campaigns} paper campaigns (median of {args.loads} loads after the first):")
    for key, value in figures.items():
        print(f"  {key:<22} {value * 1000:8.1f} ms")


if __name__ == "__main__":
    main()
