"""Sustained sample throughput of one ADXL355 through the serial-bridge driver and the simulated bridge
on a pseudo-terminal, at the part's top data rate (4 kHz), timed on the wall clock. Usage:

    python bench/bridge_throughput.py [--seconds 5]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from accelcal_rig.config.load import load_rig
from accelcal_rig.engine.clock import VirtualClock
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import SerialBridge
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.lab import VirtualLab

REPO = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    args = parser.parse_args()
    clock = VirtualClock()
    lab = VirtualLab(load_rig(REPO / "configs" / "sim.yaml").model, clock, 0)
    server = SimulatedBridgeServer(lab, 0).start()
    sensor = Adxl355(SerialBridge.open(server.path), lab.duts[0].serial, clock)
    try:
        sensor.reset()
        sensor.standby()
        sensor.configure(2, 4000.0)
        sensor.start_measurement()
        samples, start = 0, time.perf_counter()
        while time.perf_counter() - start < args.seconds:
            samples += len(sensor.acquire(4000).codes_xyz)
        wall = time.perf_counter() - start
    finally:
        sensor.close()
        server.stop()
    print(f"bridge path at 4000 Hz: {samples} gap-free samples in {wall:.2f} s wall = {samples / wall:,.0f} "
          f"samples/s per sensor (target > 4000)")


if __name__ == "__main__":
    main()
