"""What every simulated sensor bridge answers beyond its part's registers: a line far longer than the simulator's
line reader holds is refused as the reference firmware refuses any line too long (`!line too long`,
firmware/src/bridge.c), and the next request is answered. (Every other line: tests/firmware/test_bridge_conformance.py.)"""

from __future__ import annotations

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.icm42688_bridge_server import SimulatedIcm42688Bridge
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG
from tests.sim.line_client import pty_client


@pytest.mark.parametrize("bridge", [SimulatedBridgeServer, SimulatedIcm42688Bridge])
def test_a_multi_megabyte_line_is_refused_as_the_firmware_refuses_it(bridge: type) -> None:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = bridge(lab, 0).start()
    try:
        with pty_client(server.path) as client:
            for _ in range(32):  # 2 MiB, no terminator
                client.send(b"R 00 4" + b" " * 65530)
            client.send(b"\n?\n")
            assert client.reply(b"\n") == b"!line too long\n"
            assert client.reply(b"\n").startswith(b"ADXL355-BRIDGE ")
    finally:
        server.stop()
