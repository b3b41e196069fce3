"""The ACUTROL3000's acknowledgements (TM-8004-C §2; the block: protocols/acl_blocks.py): a profile that says
`length-prefixed` reads a response block after every command, its simulator sends one, byte for byte; a
controller that does the other than the rig config says is named in one line saying which override to set;
`rig check` on such a rig says what the controller does; a campaign runs on it."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols import acl_blocks
from accelcal_rig.protocols.turntable_line import turntable_protocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO, SIM_RIG

ACKED = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0, "acknowledgement": "length-prefixed"})
SILENT = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0})


def served(protocol):
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 0)
    return SimulatedTurntableServer(lab, protocol).start(), lab, clock


def raw_answer(path: str, request: bytes, expected: int) -> bytes:
    line = LinePort.open(path, "turntable", 9600, 1.0)
    try:
        line.send(request.decode())
        return line._read_block()[:expected]  # noqa: SLF001 - the bytes as they come
    finally:
        line.close()


def test_every_command_gets_a_block_byte_for_byte() -> None:
    server, lab, clock = served(ACKED)
    try:
        assert raw_answer(server.path, b":Interlock:Close 1", 10) == struct.pack("<iI", 0, 2) + b"OK"
        answer = raw_answer(server.path, b":Read:Position? 1", 64)
        code, length = struct.unpack("<iI", answer[:8])
        assert code == 0 and answer[8:] == b"0.00000" and length == 7
        refused = raw_answer(server.path, b":Demand:Posn 1,3", 128)
        code, length = struct.unpack("<iI", refused[:8])
        assert code == acl_blocks.UNKNOWN_COMMAND and refused[8:8 + length].startswith(b"ERR unknown command")
    finally:
        server.stop()


def test_the_driver_reads_a_block_after_every_command_and_moves_the_table() -> None:
    server, lab, clock = served(ACKED)
    driver = SerialTurntable.open(server.path, ACKED, n_axes=3, timeout_s=1.0)
    try:
        assert driver.identify() == "accelcal-rig simulated turntable"
        driver.move_to(np.array([30.0, -20.0, 10.0]))  # setup and the compound move: each acknowledged "OK"
        clock.sleep(10.0)
        assert [driver.in_position() for _ in range(3)][-1]
        np.testing.assert_allclose(driver.read_angles_deg(), [30, -20, 10], atol=3 / 3600 + 1e-5)
        driver.rotate_at(0, 20.0, 10.0)
        clock.sleep(5.0)
        assert driver.read_rate_deg_s(0) == pytest.approx(20.0, abs=0.5)
        with pytest.raises(InstrumentError, match=r"refused: error code 1, .ERR unknown command"):
            driver._ask_once(ACKED.identify, ":Demand:Posn 1,3")  # noqa: SLF001 - a request the table refuses
    finally:
        driver.close()
        server.stop()


@pytest.mark.parametrize(("controller", "configured", "override"), [
    (ACKED, SILENT, "acknowledgement: length-prefixed"), (SILENT, ACKED, "acknowledgement: none")])
def test_a_controller_that_does_otherwise_is_named_with_the_override(controller, configured, override) -> None:
    server, lab, clock = served(controller)
    driver = SerialTurntable.open(server.path, configured, n_axes=3, timeout_s=0.5)
    try:
        with pytest.raises(InstrumentError, match=override):
            driver.identify()
    finally:
        driver.close()
        server.stop()


def acked_rig(tmp_path, acknowledgement: str):
    rig = tmp_path / "sim.yaml"
    rig.write_text(SIM_RIG.read_text().replace(
        "protocol: accelcal-line", f"protocol: acutrol3000\n  protocol_overrides: {{acknowledgement: {acknowledgement}}}"))
    return rig


def test_rig_check_says_the_controller_acknowledges_and_a_campaign_runs(tmp_path, capsys) -> None:
    rig = acked_rig(tmp_path, "length-prefixed")
    assert main(["check", str(rig), "--dry-run", "--only", "turntable"]) == 0
    assert "acknowledges every command (length-prefixed:" in capsys.readouterr().out
    procedure = tmp_path / "quick.yaml"
    procedure.write_text((REPO / "procedures" / "quick-6pos.yaml").read_text().replace("../configs/sim.yaml", "sim.yaml"))
    assert main(["run", str(procedure), "--dry-run", "-o", str(tmp_path / "q.h5"), "-q", "--no-pdf",
                 "--no-publish"]) == 0
    assert load_campaign(tmp_path / "q.h5").state == "done"
