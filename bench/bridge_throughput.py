"""Sustained sample throughput of one ADXL355 through the serial-bridge driver and the simulated bridge
on a pseudo-terminal, at the part's top data rate (4 kHz), timed on the wall clock: with the bridge
capturing blocks itself (protocol version 2) and with the host draining the FIFO (version 1). Usage:

    python bench/bridge_throughput.py [--seconds 5] [--json]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.lab import VirtualLab

REPO = Path(__file__).resolve().parent.parent


def throughput(protocol_version: int, seconds: float) -> tuple[int, float]:
    """(gap-free samples, wall seconds) read at 4000 Hz for about `seconds`."""
    clock = VirtualClock()
    lab = VirtualLab(load_rig(REPO / "configs" / "sim.yaml").model, clock, 0)
    server = SimulatedBridgeServer(lab, 0, protocol_version).start()
    sensor = Adxl355(SerialBridge.open(server.path), lab.duts[0].serial, clock)
    try:
        sensor.reset()
        sensor.standby()
        sensor.configure({"accel": 2}, 4000.0)
        sensor.start_measurement()
        samples, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            samples += len(sensor.acquire(4000).codes["accel"])
        return samples, time.perf_counter() - start
    finally:
        sensor.close()
        server.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--json", action="store_true", help="one JSON object instead of the lines")
    args = parser.parse_args()
    paths = {}
    for version, key, how in [(2, "captured", "bridge captures blocks"), (1, "drained", "host drains the FIFO every 30 samples")]:
        samples, wall = throughput(version, args.seconds)
        paths[key] = {"protocol_version": version, "samples": samples, "wall_s": round(wall, 3),
                      "samples_per_s": round(samples / wall)}
        if not args.json:
            print(f"bridge path at 4000 Hz, {how}: {samples} gap-free samples in {wall:.2f} s wall = "
                  f"{samples / wall:,.0f} samples/s per sensor (target > 4000)")
    if args.json:
        print(json.dumps({"odr_hz": 4000.0, "seconds": args.seconds, **paths}))

if __name__ == "__main__":
    main()
