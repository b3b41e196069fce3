"""The registry at a lab's scale: 100 000 calibrations (made from one real dry-run calibration of quick-6pos,
each its own serial, part lot and date) recorded, then the queries an operator makes — a serial's history
and valid calibration, a date-filtered list, a part's lot statistics, one calibration's stored fit — timed
on the wall clock. SQLite by default; `--url postgresql://…` for a PostgreSQL server. Usage:

    python bench/registry.py [--count 100000] [--url URL] [--json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import uuid
from datetime import timedelta
from pathlib import Path

from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.registry.analysis import lot_statistics, trend
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.entries import campaign_entries
from accelcal_rig.registry.location import described, normalised

REPO = Path(__file__).resolve().parent.parent
#: Calibrations per serial (recalibrations), and serials per part lot.
PER_SERIAL = 5
PARTS = ("adxl355", "adxl357", "adxl359", "bmi088")
#: The channel a valid calibration, a trend and a lot's statistics are of (the registry keeps a row per channel).
CHANNEL = "accel"


def template_entry(folder: Path) -> dict:
    silence_campaign_log()
    campaign = folder / "quick.h5"
    calibration = folder / "quick.calibration.yaml"
    run_campaign(prepare(REPO / "procedures" / "quick-6pos.yaml"), campaign, dry_run=True, seed=0, overwrite=False,
                 calibration=calibration)
    return campaign_entries(campaign, calibration)[0]


def entries(template: dict, count: int) -> list[dict]:
    made = []
    for k in range(count):
        serial = k // PER_SERIAL
        made.append(template | {"serial": f"LAB-{serial:06d}", "part": PARTS[serial % len(PARTS)],
                                "fit_sha256": uuid.uuid5(uuid.NAMESPACE_OID, str(k)).hex * 2,
                                "calibrated_at": template["calibrated_at"] + timedelta(days=90 * (k % PER_SERIAL),
                                                                                      seconds=k)})
    return made


def timed(what: str, action, figures: dict, repeat: int = 1):  # noqa: ANN001, ANN201
    start = time.perf_counter()
    for _ in range(repeat):
        result = action()
    figures[what] = (time.perf_counter() - start) / repeat
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=100_000)
    parser.add_argument("--url", help="registry URL (default: a new SQLite file in a temporary folder)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        url = normalised(args.url or str(Path(folder) / "registry.sqlite"))
        made = entries(template_entry(Path(folder)), args.count)
        figures: dict[str, float] = {}
        registry = timed("open_and_create_s", lambda: Registry.open(url), figures)
        added, _ = timed("insert_s", lambda: registry.add(made), figures)
        assert len(added) == args.count
        figures["insert_per_s"] = args.count / figures["insert_s"]
        timed("add_again_s", lambda: registry.add(made[:1000]), figures)  # 1000 already registered: skipped
        serial = made[args.count // 2]["serial"]
        timed("history_of_a_serial_s", lambda: registry.calibrations(serial=serial), figures, repeat=20)
        timed("valid_calibration_s", lambda: registry.current(serial, channel=CHANNEL), figures, repeat=20)
        timed("trend_s", lambda: trend(registry.calibrations(serial=serial, channel=CHANNEL), CHANNEL), figures,
              repeat=20)
        since = made[0]["calibrated_at"] + timedelta(days=300)
        listed = timed("list_since_date_s", lambda: registry.calibrations(since=since), figures)
        figures["listed"] = len(listed)
        stats = timed("lot_statistics_of_a_part_s",
                      lambda: lot_statistics(registry.calibrations(part="adxl355", channel=CHANNEL), CHANNEL), figures)
        figures["lot_sensors"] = stats["sensors"]
        timed("stored_fit_by_id_s", lambda: registry.calibration(added[len(added) // 3]), figures, repeat=20)
        if url.startswith("sqlite:///"):
            figures["file_mb"] = Path(url.removeprefix("sqlite:///")).stat().st_size / 1e6
    if args.json:
        print(json.dumps({"url": described(url), "count": args.count, **figures}))
        return
    print(f"registry {described(url).split('?')[0]}: {args.count} calibrations")
    for key, value in figures.items():
        print(f"  {key:<28} {value:,.4g}")


if __name__ == "__main__":
    main()
