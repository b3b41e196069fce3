"""The acutrol3000 profile against its simulator on a pseudo-terminal: the simulated table moves only once
armed by the setup, all axes start together, completion comes by rate, a tripped interlock names its axis;
and a quick campaign runs on it."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.cli import main
from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.turntable_line import turntable_protocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO, SIM_RIG

ACUTROL = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0})


@pytest.fixture
def table():
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 0)
    server = SimulatedTurntableServer(lab, ACUTROL).start()
    driver = SerialTurntable.open(server.path, ACUTROL, n_axes=3, timeout_s=1.0)
    yield driver, server, lab, clock
    driver.close()
    server.stop()


def test_all_axes_start_together_and_complete_by_rate(table) -> None:
    driver, server, lab, clock = table
    driver.move_to(np.array([100.0, 90.0, -45.0]))  # one line: every axis starts at once
    driver.read_angles_deg()  # unanswered, the move is taken in order before the next request
    assert server.last_command == ":demand:position 1,100.00000;:demand:position 2,90.00000;:demand:position 3,-45.00000"
    clock.sleep(1.0)
    assert not driver.in_position()
    assert np.all(np.abs(lab.motion.rate_deg_s(clock.now())) > 0)  # all three moving at once
    clock.sleep(5.0)
    assert [driver.in_position() for _ in range(3)] == [False, False, True]  # three polls at rest
    np.testing.assert_allclose(driver.read_angles_deg(), [100, 90, -45], atol=3 / 3600 + 1e-5)


def test_the_simulated_table_ignores_a_move_before_it_is_armed_and_after_a_stop(table) -> None:
    driver, server, lab, clock = table
    line = LinePort.open(server.path, "turntable", 9600, 1.0)
    try:
        line.send(":demand:position 1,30.00000")  # no interlock closed, no position mode
        line.ask("*IDN?")  # answered after the move was taken: the simulator has seen it
        clock.sleep(10.0)
        assert lab.motion.position_deg(clock.now())[0] == pytest.approx(0.0)
        driver.move_to(np.array([30.0, 0.0, 0.0]))  # the driver arms the table first
        driver.read_angles_deg()
        clock.sleep(10.0)
        assert lab.motion.position_deg(clock.now())[0] == pytest.approx(30.0, abs=0.01)
        driver.stop()  # rate mode now: the next move must set the table up again, and does
        driver.move_to(np.array([60.0, 0.0, 0.0]))
        driver.read_angles_deg()
        clock.sleep(10.0)
        assert lab.motion.position_deg(clock.now())[0] == pytest.approx(60.0, abs=0.01)
    finally:
        line.close()


def test_a_bad_part_of_a_compound_move_moves_nothing_and_the_simulator_lives_on(table) -> None:
    driver, server, lab, clock = table
    driver.move_to(np.array([0.0, 0.0, 0.0]))  # armed
    line = LinePort.open(server.path, "turntable", 9600, 1.0)
    try:
        assert line.ask(":demand:position 1,30.00000;:demand:position 9,2.00000") == "ERR no axis 9"
        clock.sleep(10.0)
        assert lab.motion.position_deg(clock.now())[0] == pytest.approx(0.0, abs=0.01)
        assert line.ask("*IDN?") == "accelcal-rig simulated turntable"
    finally:
        line.close()


def test_a_tripped_interlock_on_one_axis_is_named(table) -> None:
    driver, server, _, _ = table
    server.faults[1] = "Fault"
    with pytest.raises(InstrumentError, match=r"turntable \(serial /dev/pts/\d+\): axis 2: controller fault Fault"):
        driver.in_position()


def test_a_quick_campaign_runs_on_the_acutrol_profile(tmp_path, capsys) -> None:
    rig = tmp_path / "sim.yaml"
    rig.write_text(SIM_RIG.read_text().replace("protocol: accelcal-line", "protocol: acutrol3000"))
    procedure = tmp_path / "quick.yaml"
    procedure.write_text((REPO / "procedures" / "quick-6pos.yaml").read_text().replace("../configs/sim.yaml", "sim.yaml"))
    assert main(["run", str(procedure), "--dry-run", "-o", str(tmp_path / "q.h5"), "-q", "--no-pdf"]) == 0
    stored = load_campaign(tmp_path / "q.h5")
    assert stored.state == "done" and len(stored.poses) == 12
    assert "protocol: acutrol3000" in rig.read_text()
