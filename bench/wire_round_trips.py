"""Where the time of a dry run through the wire-level simulators goes: every request to an instrument,
counted and timed by kind, over one paper campaign. Usage:

    python bench/wire_round_trips.py
"""

from __future__ import annotations

import tempfile
import time
from collections import defaultdict
from pathlib import Path

from quiet import silence_campaign_log  # bench/quiet.py, beside this script

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.instruments import chamber_modbus, line_port

REPO = Path(__file__).resolve().parent.parent


def main() -> None:
    silence_campaign_log()
    counts: dict[str, list[float]] = defaultdict(lambda: [0, 0.0])

    def timed(key_of, function):
        def wrapper(self, *args):
            start = time.perf_counter()
            result = function(self, *args)
            entry = counts[key_of(self, *args)]
            entry[0] += 1
            entry[1] += time.perf_counter() - start
            return result
        return wrapper

    line_port.LinePort.ask = timed(lambda self, request: f"{self.name.split(' (')[0]} {request.split()[0]}",
                                   line_port.LinePort.ask)
    chamber_modbus.ModbusChamber._read = timed(lambda self, address, count: f"chamber read {address}",
                                               chamber_modbus.ModbusChamber._read)
    chamber_modbus.ModbusChamber._write = timed(lambda self, address, values: f"chamber write {address}",
                                                chamber_modbus.ModbusChamber._write)
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        run_campaign(prepare(REPO / "procedures" / "paper-24pos-thermal.yaml"), Path(folder) / "c.h5",
                     dry_run=True, seed=0, overwrite=False)
        total = time.perf_counter() - start
    on_wire = sum(seconds for _, seconds in counts.values())
    print(f"paper campaign through the wire: {total:.2f} s, of which {on_wire:.2f} s waiting on "
          f"{sum(int(n) for n, _ in counts.values())} requests")
    for key, (n, seconds) in sorted(counts.items(), key=lambda item: -item[1][1]):
        print(f"  {key:24s} {int(n):6d} requests {seconds:6.2f} s  {seconds / n * 1e3:.3f} ms each")


if __name__ == "__main__":
    main()
