"""The ADXL355 driver through the serial bridge, against the simulated part on a pseudo-terminal."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.fit.sfem import distort
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import SerialBridge, SpidevBus
from accelcal_rig.instruments.capture import capture_together
from accelcal_rig.parts.adxl35x import ADXL355
from accelcal_rig.sim.adxl355_bridge_server import SimulatedBridgeServer
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.pty_line_server import PtyLineServer
from tests.conftest import SIM_RIG


@contextmanager
def opened_sensor(protocol_version: int):
    """(driver, server, lab, clock) of DUT 2 behind a simulated bridge speaking `protocol_version`."""
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    server = SimulatedBridgeServer(lab, 1, protocol_version).start()
    driver = Adxl355(SerialBridge.open(server.path), "ADX355-A002", clock)
    try:
        yield driver, server, lab, clock
    finally:
        driver.close()
        server.stop()


@pytest.fixture(params=[1, 2], ids=["host-drains-fifo", "bridge-captures"])
def sensor(request):
    """Both ways to a block: the host draining the FIFO (a version 1 bridge, as spidev) and the bridge's
    own capture (version 2)."""
    with opened_sensor(request.param) as opened:
        yield opened


@pytest.fixture
def fifo_sensor():
    with opened_sensor(1) as (driver, *_):
        yield driver


@pytest.fixture
def capturing_sensor():
    with opened_sensor(2) as (driver, *_):
        yield driver


def bring_up(driver: Adxl355, range_g: int = 2, odr_hz: float = 125.0) -> None:
    driver.reset()
    driver.standby()
    driver.configure({"accel": range_g}, odr_hz)
    driver.start_measurement()


def test_identity_and_temperature(sensor) -> None:
    driver, _, lab, _ = sensor
    identity = driver.identify()
    assert identity.registers == (0xAD, 0x1D, 0xED)
    assert driver.read_temperature_c() == pytest.approx(lab.dut_true_c(1), abs=0.3)


def test_blocks_are_gap_free_and_match_the_truth(sensor) -> None:
    driver, _, lab, clock = sensor
    bring_up(driver)
    block = driver.acquire(1000)
    assert block.codes["accel"].shape == (1000, 3) and block.codes["accel"].dtype == np.int32
    assert block.t_end_s - block.t_start_s == pytest.approx(999 / 125)
    truth = lab.truth_between(1, block.t_start_s, block.t_end_s)
    expected = distort(truth["gravity_g"], truth["parameters"])
    measured = block.codes["accel"] * ADXL355.channel("accel").lsb(2)
    noise = lab.noise_g(0, 125.0)
    np.testing.assert_allclose(measured.mean(axis=0), expected, atol=5 * noise / np.sqrt(1000))
    # gap-free white noise: no step between drains, lag-1 correlation ≈ 0
    centred = measured - measured.mean(axis=0)
    lag1 = np.sum(centred[1:] * centred[:-1], axis=0) / np.sum(centred**2, axis=0)
    assert np.all(np.abs(lag1) < 0.1)


def test_range_setting_changes_the_codes(sensor) -> None:
    driver, _, _, _ = sensor
    bring_up(driver, range_g=8)
    block = driver.acquire(100)
    assert np.abs(block.codes["accel"].mean(axis=0)).max() == pytest.approx(64000, rel=0.05)  # ~1 g at ±8 g


def test_configure_outside_standby_is_refused(sensor) -> None:
    driver, _, _, _ = sensor
    bring_up(driver)
    with pytest.raises(InstrumentError, match="only change in standby"):
        driver.configure({"accel": 4}, 125.0)


def test_the_greeting_says_whether_the_bridge_captures(sensor) -> None:
    driver, server, _, _ = sensor
    expected = 4096 if server.version >= 2 else 0
    assert driver.capture_capacity_samples == expected


def test_a_fifo_the_link_cannot_keep_up_with_is_a_fault(fifo_sensor, monkeypatch) -> None:
    bring_up(fifo_sensor, odr_hz=4000.0)
    monkeypatch.setattr("accelcal_rig.instruments.adxl355_driver.DRAIN_EVERY_SAMPLES", 80)  # > 32: overflows
    with pytest.raises(InstrumentError, match="FIFO overflowed in 3 attempts"):
        fifo_sensor.acquire(200)


def test_a_capture_that_keeps_losing_samples_is_a_fault() -> None:
    clock = VirtualClock()
    replies = {"?": "ADXL355-BRIDGE 2 capture=512 test", "R": "=000007A0", "C": "=07A0", "G": "!overflow: FIFO"}
    server = PtyLineServer(lambda request: replies[request[0]]).start()
    try:
        driver = Adxl355(SerialBridge.open(server.path), "SN-1", clock)
        with pytest.raises(InstrumentError, match="FIFO overflowed in 3 attempts"):
            driver.acquire(100)
        driver.close()
    finally:
        server.stop()


def test_a_lost_fetch_reply_is_asked_for_again_without_losing_samples(capturing_sensor) -> None:
    bring_up(capturing_sensor)
    bridge = capturing_sensor._bus
    real_fetch, calls = bridge.fetch_capture, []

    def lossy_fetch(first: int):
        calls.append(first)
        reply = real_fetch(first)
        if len(calls) == 1:
            raise InstrumentError("reply lost on the line")  # the bridge answered; the host never heard it
        return reply

    bridge.fetch_capture = lossy_fetch
    capturing_sensor.begin_capture(100)
    capturing_sensor._clock.sleep(capturing_sensor.capture_wait_s())
    with pytest.raises(InstrumentError):
        capturing_sensor.fetch_capture()
    assert capturing_sensor.fetch_capture()  # asked again from the same index: complete
    block = capturing_sensor.end_capture()
    assert calls == [0, 0] and block.codes["accel"].shape == (100, 3)


def test_a_sensor_in_standby_gives_no_samples_before_the_deadline(fifo_sensor) -> None:
    fifo_sensor.standby()
    with pytest.raises(InstrumentError, match="0 of 50 samples before the deadline: is it measuring"):
        fifo_sensor.acquire(50)


def test_a_bridge_refuses_to_capture_from_a_sensor_in_standby(capturing_sensor) -> None:
    capturing_sensor.standby()
    with pytest.raises(InstrumentError, match=r"'C 50' refused: capture needs the part measuring"):
        capturing_sensor.acquire(50)


def test_bridge_protocol_bytes_and_refusals() -> None:
    seen = []

    def bridge(request: str) -> str:
        seen.append(request)
        if request == "?":
            return "ADXL355-BRIDGE 1 test"
        if request.startswith("R 00"):
            return "=AD1DE901"  # an ADXL359
        return "!not supported"

    server = PtyLineServer(bridge).start()
    try:
        transport = SerialBridge.open(server.path)
        identity = Adxl355(transport, "SN-9", VirtualClock()).identify()
        assert identity.registers[2] == 0xE9
        with pytest.raises(InstrumentError, match=r"'W 2D 00' refused: not supported"):
            transport.write(0x2D, 0x00)
        transport.close()
    finally:
        server.stop()
    assert seen == ["?", "R 00 4", "W 2D 00"]


def test_something_that_is_not_a_bridge_is_named() -> None:
    server = PtyLineServer(lambda request: "hello from a modem").start()
    try:
        with pytest.raises(InstrumentError, match=r"sensor bridge \(serial /dev/pts/\d+\): not an ADXL355 bridge"):
            SerialBridge.open(server.path, timeout_s=0.5)
    finally:
        server.stop()


def test_spidev_missing_is_a_clear_error(monkeypatch) -> None:
    import builtins

    real_import = builtins.__import__

    def no_spidev(name, *args, **kwargs):
        if name == "spidev":
            raise ImportError("no spidev")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_spidev)
    with pytest.raises(InstrumentError, match=r"spidev is not installed: pip install 'accelcal-rig\[spi\]' "
                                              r"\(its packages: pip install 'spidev>=[0-9.]+'\)"):
        SpidevBus.open(0, 0)


@pytest.mark.parametrize(("greeting", "capacity"), [
    ("ADXL355-BRIDGE 1 test", 0), ("ADXL355-BRIDGE 2 capture=512 fw 0.3", 512),
    ("ADXL355-BRIDGE 2 fw 0.3", 0), ("ADXL355-BRIDGE 2 capture=lots", 0)])
def test_capture_capacity_comes_from_the_greeting(greeting: str, capacity: int) -> None:
    server = PtyLineServer(lambda request: greeting).start()
    try:
        transport = SerialBridge.open(server.path)
        assert transport.capture_capacity_samples == capacity
        transport.close()
    finally:
        server.stop()


@pytest.mark.parametrize(("request_kind", "reply", "message"), [
    ("C", "=", r"capture of 10 answered '='"),
    ("G 0", "=00112", "garbled capture"),
    ("G 0", "=T07", "garbled capture"),
    ("G", "!overflow: 4097 samples", r"overflow: 4097 samples")])
def test_capture_replies_are_checked(request_kind: str, reply: str, message: str) -> None:
    def bridge(request: str) -> str:
        if request == "?":
            return "ADXL355-BRIDGE 2 capture=64 test"
        return reply if request.startswith(request_kind) else "=0761"

    server = PtyLineServer(bridge).start()
    try:
        transport = SerialBridge.open(server.path)
        with pytest.raises(InstrumentError, match=message):
            transport.start_capture(10)
            transport.fetch_capture(0)
        transport.close()
    finally:
        server.stop()


def test_torn_temperature_reads_from_the_part_never_reach_the_campaign() -> None:
    """A simulated part that tears 2 % of its TEMP2/TEMP1 reads: one read alone is off by ~28 °C now and
    then; the driver's reading never is (it would take two torn reads in a row, torn the same way)."""
    from accelcal_rig.instruments import adxl355

    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    server = SimulatedBridgeServer(lab, 1, 2, temperature_tear_rate=0.02).start()
    bus = SerialBridge.open(server.path)
    driver = Adxl355(bus, "ADX355-A002", clock)
    try:
        true_c = lab.dut_true_c(1)
        single = [ADXL355.temperature.celsius(adxl355.raw_temperature(*bus.read(adxl355.REG_TEMP2, 2)))
                  for _ in range(500)]
        assert sum(abs(t - true_c) > 20 for t in single) >= 3  # the quirk is there: the old single read fails
        readings = np.array([driver.read_temperature_c() for _ in range(100)])
        assert np.all(np.abs(readings - true_c) < 0.5)
    finally:
        driver.close()
        server.stop()


def test_torn_reads_in_the_status_burst_of_a_drained_block_are_outvoted_too() -> None:
    """A version 1 bridge (and spidev): the host drains the FIFO and reads STATUS..TEMP1 in one burst around
    the block; those temperatures are the pose's."""
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    server = SimulatedBridgeServer(lab, 1, 1, temperature_tear_rate=0.05).start()
    driver = Adxl355(SerialBridge.open(server.path), "ADX355-A002", clock)
    try:
        bring_up(driver)
        true_c = lab.dut_true_c(1)
        for _ in range(20):
            block = driver.acquire(30)
            assert all(abs(t - true_c) < 0.5 for t in block.temperature_c)
    finally:
        driver.close()
        server.stop()


def test_a_capture_started_together_is_timed_from_its_request_not_from_when_its_reply_was_read() -> None:
    """Two bridges asked to capture at once; the first's reply is lost and its retried request lost again,
    so the retry waits out a backoff on the campaign clock before the second's reply (there since the
    request) is read. Each block must be timed from when its own capture began on the bridge: the second's
    at the request, the first's at its retry. Timed from the reply, the second block claimed samples the
    bridge took 0.5 s earlier (a dry run then found no truth behind it and aborted the campaign)."""
    clock, backoff_s, n_samples = VirtualClock(), 0.5, 50  # a block of 0.4 s, shorter than the backoff
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    servers = [SimulatedBridgeServer(lab, index, 2).start() for index in (0, 1)]
    bridges = [SerialBridge.open(server.path) for server in servers]
    drivers = [Adxl355(bridge, f"ADX355-A00{index + 1}", clock) for index, bridge in enumerate(bridges)]

    def retried(operation, reconnect=None):
        """The engine's retry in small: a transient failure waits a backoff on the clock, then tries again."""
        for _ in range(3):
            try:
                return operation()
            except TransientInstrumentError:
                clock.sleep(backoff_s)
        return operation()

    real_receive, lost = bridges[0].receive_capture, []

    def lossy_receive(n: int) -> int:
        reply = real_receive(n)  # the bridge started the capture and answered; the host never heard it
        if len(lost) < 2:
            lost.append(n)
            raise TransientInstrumentError("reply lost on the line")
        return reply

    bridges[0].receive_capture = lossy_receive
    try:
        for driver in drivers:
            driver.retry_exchanges(retried)
            bring_up(driver)
        asked_s = clock.now()
        blocks = capture_together(drivers, n_samples, clock)
        assert lost == [n_samples, n_samples]
        assert blocks[0].t_start_s == pytest.approx(asked_s + backoff_s, abs=1 / 125)  # started again by the retry
        assert blocks[1].t_start_s == pytest.approx(asked_s, abs=1 / 125)  # started by the request posted first
        for index, block in enumerate(blocks):
            truth = lab.truth_between(index, block.t_start_s, block.t_end_s)  # raised for the second before
            assert truth["gravity_g"].shape == (3,)
    finally:
        for driver, server in zip(drivers, servers):
            driver.close()
            server.stop()


def test_a_lost_reply_to_the_status_that_ends_a_drained_block_is_never_retried_alone() -> None:
    """A version 1 bridge (the host drains the FIFO): STATUS's FIFO_OVR clears as it is read, so the read that
    ends a block is not retried by itself when its reply is lost — the retry would read a cleared flag and pass a
    block that lost samples. The loss reaches the caller, who takes the block again whole."""
    from accelcal_rig.instruments import adxl355

    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 3)
    server = SimulatedBridgeServer(lab, 1, 1).start()
    bus = SerialBridge.open(server.path)
    driver = Adxl355(bus, "ADX355-A002", clock)
    retries: list[int] = []

    def retried(operation, reconnect=None):
        for attempt in range(3):
            try:
                return operation()
            except TransientInstrumentError:
                retries.append(attempt)
        return operation()

    real_read, status_reads = bus.read, []

    def lossy_read(register: int, count: int) -> bytes:
        reply = real_read(register, count)
        if register == adxl355.REG_STATUS and count == 4:
            status_reads.append(reply[0])
            if len(status_reads) == 3:  # the block's closing STATUS: read (and cleared) on the part, then lost
                raise TransientInstrumentError("reply lost on the line")
        return reply

    try:
        driver.retry_exchanges(retried)
        bring_up(driver)
        bus.read = lossy_read  # type: ignore[method-assign]
        with pytest.raises(TransientInstrumentError, match="reply lost"):
            driver.acquire(30)
        assert len(status_reads) == 3 and retries == []   # not retried alone
        bus.read = real_read  # type: ignore[method-assign]
        assert len(driver.acquire(30).codes["accel"]) == 30  # taken again whole
    finally:
        driver.close()
        server.stop()
