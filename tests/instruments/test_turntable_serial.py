"""The serial turntable driver against the simulated controller on a pseudo-terminal."""

from __future__ import annotations

import os
import threading
import time
import tty

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.limits import LimitedTurntable
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.turntable_line import ACCELCAL_LINE, turntable_protocol
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer
from accelcal_rig.sim.turntable_server import SimulatedTurntableServer
from tests.conftest import SIM_RIG


@pytest.fixture
def table():
    clock = VirtualClock()
    rig = load_rig(SIM_RIG).model
    lab = VirtualLab(rig, clock, 0)
    server = SimulatedTurntableServer(lab, ACCELCAL_LINE).start()
    driver = SerialTurntable.open(server.path, ACCELCAL_LINE, n_axes=3, timeout_s=1.0)
    yield driver, server, lab, clock
    driver.close()
    server.stop()


def test_move_poll_and_read_back_over_the_wire(table) -> None:
    driver, _, lab, clock = table
    assert driver.identify() == "accelcal-rig simulated turntable"
    driver.move_to(np.array([0.0, 90.0, -45.0]))  # 90° at 20°/s: 4.5 s, then 0.5 s settle
    clock.sleep(2.0)
    assert not driver.in_position()
    np.testing.assert_allclose(driver.read_angles_deg(), [0, 40, -40], atol=1e-3)
    clock.sleep(3.1)
    assert driver.in_position()
    np.testing.assert_allclose(driver.read_angles_deg(), [0, 90, -45], atol=3 / 3600 + 1e-5)
    np.testing.assert_allclose(lab.motion.last_command_deg, [0, 90, -45])


def test_stop_holds_where_the_table_is(table) -> None:
    driver, _, _, clock = table
    driver.move_to(np.array([0.0, 90.0, 0.0]))
    clock.sleep(1.0)
    driver.stop()
    clock.sleep(10.0)
    assert driver.in_position()
    assert driver.read_angles_deg()[1] == pytest.approx(20.0, abs=1e-3)


def test_controller_fault_is_raised_not_waited_out(table) -> None:
    driver, server, _, _ = table
    server.fault = "7"
    with pytest.raises(InstrumentError, match=r"turntable \(serial /dev/pts/\d+\): controller fault 7"):
        driver.in_position()


def test_exact_bytes_of_the_built_in_profile() -> None:
    seen = []
    server = PtyLineServer(lambda request: seen.append(request) or "OK").start()
    try:
        driver = SerialTurntable.open(server.path, ACCELCAL_LINE, n_axes=2, timeout_s=1.0)
        driver.move_to(np.array([12.5, -0.25]))
        driver.stop()
        driver.close()
    finally:
        server.stop()
    assert seen == ["MOV 1 12.50000", "MOV 2 -0.25000", "STOP"]


def test_error_replies_garbage_and_silence_are_one_line_errors() -> None:
    replies = iter(["ERR axis 2 not homed", "what?"])
    server = PtyLineServer(lambda request: next(replies)).start()
    driver = SerialTurntable.open(server.path, ACCELCAL_LINE, n_axes=2, timeout_s=0.3)
    try:
        with pytest.raises(InstrumentError, match=r"'MOV 1 0.00000' refused: 'ERR axis 2 not homed'"):
            driver.move_to(np.zeros(2))
        with pytest.raises(InstrumentError, match=r"'BUSY\?': unexpected reply 'what\?'"):
            driver._ask(ACCELCAL_LINE.busy)
    finally:
        driver.close()
        server.stop()


def test_a_dead_port_is_named() -> None:
    with pytest.raises(InstrumentError, match=r"turntable \(serial /dev/nonexistent-port\): cannot open"):
        SerialTurntable.open("/dev/nonexistent-port", ACCELCAL_LINE, n_axes=2)


def test_no_reply_within_the_timeout() -> None:
    server = PtyLineServer(lambda request: "OK", terminator=b"\r").start()  # answers, but never a '\n'
    driver = SerialTurntable.open(server.path, ACCELCAL_LINE, n_axes=1, timeout_s=0.3)
    try:
        with pytest.raises(InstrumentError, match="no reply within the timeout"):
            driver.identify()
    finally:
        driver.close()
        server.stop()


def test_profile_overrides_are_validated() -> None:
    crlf = turntable_protocol("accelcal-line", {"write_terminator": "\r\n", "read_terminator": "\r\n"})
    assert crlf.read_terminator == "\r\n"
    with pytest.raises(ValueError, match="not a regular expression"):
        turntable_protocol("accelcal-line", {"busy": {"send": "B?", "reply": "(", "answer": "0"}})


def test_limits_gate_the_serial_driver(table) -> None:
    from accelcal_rig.config.rig import TurntableAxis, TurntableConfig

    driver, _, lab, _ = table
    config = TurntableConfig(axes=[TurntableAxis(name=n, axis=(0, 0, 1), min_deg=-90, max_deg=90) for n in "abc"])
    with pytest.raises(InstrumentError, match="axis b to 120° refused"):
        LimitedTurntable(driver, config).move_to(np.array([0.0, 120.0, 0.0]))
    assert np.all(np.isnan(lab.motion.last_command_deg))  # nothing reached the controller


def test_a_device_that_never_ends_its_line_is_cut_off_at_the_timeout() -> None:
    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    stop = threading.Event()

    def babble() -> None:  # a controller stuck sending bytes, never a terminator
        while not stop.is_set():
            os.write(master, b"garbage ")
            time.sleep(0.001)

    writer = threading.Thread(target=babble, daemon=True)
    writer.start()
    driver = SerialTurntable.open(os.ttyname(slave), ACCELCAL_LINE, n_axes=1, timeout_s=0.3)
    try:
        started = time.monotonic()
        with pytest.raises(InstrumentError, match="no reply within the timeout"):
            driver.identify()
        assert time.monotonic() - started < 10.0  # gave up (0.3 s), not read for ever; a busy machine's margin
    finally:
        stop.set()
        writer.join(2)
        driver.close()
        os.close(master)
        os.close(slave)
