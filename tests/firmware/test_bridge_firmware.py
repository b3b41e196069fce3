"""The bridge's reference firmware (firmware/): its core built for the host in front of the C model of an
ADXL355, on a pseudo-terminal, driven by the project's own driver exactly as a board on a serial port would
be. (The core's cross-compiled build for the board, and its RAM bound, are `make -C firmware cross`: a CI step
of its own, as it needs the ARM toolchain a developer's machine may not have.)

The host firmware runs on the board clock (`--clock board`, firmware/host/pty_hal.h), which both its core and
the model of the part keep time by: the time a board running only this firmware would see. It moves on by the
CPU time the process uses, by each of its sleeps up to the timeout the sleep asked for, and by the whole time
the process is stopped (SIGSTOP, a stalled board); not by time spent waiting for a CPU or in a sleep's
overrun. A PC busy with other work can leave the process unscheduled for longer than the FIFO lasts (8 ms at
4 kHz), and on the plain monotonic clock the model would then lose samples no board would lose. A core that
drains too seldom, or one that stalls, still overflows on the board clock, and the board clock never runs
ahead of the wall clock.

Waits on the firmware are polls against a generous deadline, never a guessed sleep; the sleeps left are the
time under test (a stall's length, a partial line's age)."""

from __future__ import annotations

import os
import re
import signal
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.core.clock import RealClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import CaptureOverflow, SerialBridge
from accelcal_rig.instruments.line_port import LinePort
from accelcal_rig.parts.adxl35x import ADXL355
from tests.firmware.host_firmware import DEADLINE_S, SEED, Firmware, running, wait_until

# The C model's facts (firmware/host/adxl355_model.h): what every capture through the firmware must give back.
GRAVITY_UG = np.array([200_000, -400_000, 894_000])
NOISE_LSB = {2: 26, 4: 13, 8: 6}  # uniform within ±100 µg, rounded to whole LSB
TEMPERATURE_C = 31.0  # what the tests tell the model its temperature sensor reads


@dataclass
class Opened:
    driver: Adxl355
    bridge: SerialBridge
    firmware: Firmware


@contextmanager
def opened(binary: Path, *options: str) -> Iterator[Opened]:
    """The project's driver on the firmware's port, on the wall clock (the model's samples come at their rate
    on the board clock, which never runs ahead of the wall clock)."""
    with running(binary, "--temperature-c", str(TEMPERATURE_C), *options) as firmware:
        bridge = SerialBridge.open(firmware.path)
        try:
            yield Opened(Adxl355(bridge, "FW-0001", RealClock()), bridge, firmware)
        finally:
            bridge.close()


@pytest.fixture
def sensor(bridge_host: Path) -> Iterator[Opened]:
    with opened(bridge_host) as found:
        yield found


@pytest.fixture
def line(bridge_host: Path) -> Iterator[LinePort]:
    """The bare line to the firmware, for requests the driver never sends."""
    with running(bridge_host) as firmware:
        port = LinePort.open(firmware.path, "bridge", 921600, 1.0)
        try:
            yield port
        finally:
            port.close()


def bring_up(driver: Adxl355, range_g: int, odr_hz: float) -> None:
    driver.reset()
    driver.standby()
    driver.configure({"accel": range_g}, odr_hz)
    driver.start_measurement()


def model_codes(first: int, count: int, range_g: int) -> np.ndarray:
    """Samples `first` … `first + count - 1` since measuring began, as the C model makes them: the gravity
    vector's codes plus the lowbias32 hash of each entry's index, reduced to ±NOISE_LSB."""
    x = (np.arange(3 * first, 3 * (first + count), dtype=np.uint64) + SEED).astype(np.uint32)
    x ^= x >> np.uint32(16)
    x *= np.uint32(0x7FEB352D)
    x ^= x >> np.uint32(15)
    x *= np.uint32(0x846CA68B)
    x ^= x >> np.uint32(16)
    amplitude = NOISE_LSB[range_g]
    noise = (x % np.uint32(2 * amplitude + 1)).astype(np.int64) - amplitude
    gravity_codes = GRAVITY_UG * int(ADXL355.channel("accel").lsb_per_unit[range_g]) // 1_000_000
    return (gravity_codes + noise.reshape(-1, 3)).astype(np.int32)


def process_state(pid: int) -> str:
    """The state letter of /proc/<pid>/stat ("T": stopped)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return stat[stat.rindex(")") + 2]


def first_sample_index(codes: np.ndarray, range_g: int, search: int = 200_000) -> int:
    """Where in the model's sequence a block starts, if it is that sequence unbroken; else the test fails."""
    sequence = model_codes(0, search + len(codes), range_g)
    for start in np.flatnonzero((sequence[:search] == codes[0]).all(axis=1)):
        if np.array_equal(sequence[start:start + len(codes)], codes):
            return int(start)
    raise AssertionError("the block is not the model's samples in unbroken order (a gap, a repeat or a corrupt byte)")


def test_the_greeting_names_protocol_3_its_part_and_its_4096_sample_buffer(line: LinePort, sensor: Opened) -> None:
    """The driver decides by the greeting whether the bridge captures, and how much at once; version 3 also
    names the part the firmware found on SPI (by DEVID_AD, for an ADXL355)."""
    assert re.fullmatch(r"ADXL355-BRIDGE 3 part=adxl355 capture=4096 accelcal-rig reference firmware .+ \(host\)",
                        line.ask("?"))
    assert sensor.driver.capture_capacity_samples == 4096
    assert sensor.bridge.part_name == "adxl355"


def test_identity_reset_and_register_round_trips(sensor: Opened) -> None:
    """Register access is the SPI framing the driver relies on: reads in bursts, writes one at a time."""
    driver, bridge = sensor.driver, sensor.bridge
    identity = driver.identify()
    assert (identity.registers, identity.revision) == ((0xAD, 0x1D, 0xED), 0x01)
    bridge.write(0x1E, 0x5A)  # OFFSET_X_H: a register nothing else touches
    assert bridge.read(0x1E, 1) == b"\x5a"
    bring_up(driver, 4, 1000.0)
    assert driver.read_settings() == ({"accel": 4}, 1000.0)
    driver.reset()
    assert bridge.read(0x1E, 1) == b"\x00"
    assert bridge.read(adxl355.REG_RANGE, 2) == bytes([0x81, 0x01])  # RANGE and POWER_CTL at their reset values
    assert driver.read_temperature_c() == pytest.approx(TEMPERATURE_C, abs=0.3)


@pytest.mark.parametrize(("range_g", "odr_hz", "n_samples"), [(2, 1000.0, 400), (8, 4000.0, 4096)],
                         ids=["400-at-1kHz", "whole-buffer-at-4kHz"])
def test_captures_are_the_models_samples_unbroken(sensor: Opened, range_g: int, odr_hz: float, n_samples: int) -> None:
    """A capture through the firmware: every sample the model made, in order, none lost or repeated,
    decoding to the model's gravity vector, with the model's temperature at both ends. At 4 kHz the FIFO
    lasts 8 ms, so for the whole buffer (a second) the core must drain it in time at every turn, and between
    the chunks of its replies, or the capture overflows (three times, and the driver raises). Time is the
    board clock's: this proves the core keeps up when it has a processor to itself, as on a board, not that
    a process on a busy PC is scheduled every 8 ms."""
    driver = sensor.driver
    bring_up(driver, range_g, odr_hz)
    started = time.monotonic()
    block = driver.acquire(n_samples)
    # Samples at the part's own rate, not faster (a lower bound: a slow machine only makes it longer).
    assert time.monotonic() - started >= (n_samples - 1) / odr_hz
    assert block.codes["accel"].shape == (n_samples, 3)
    first_sample_index(block.codes["accel"], range_g)
    measured_g = block.codes["accel"] * ADXL355.channel("accel").lsb(range_g)
    noise_g = NOISE_LSB[range_g] * ADXL355.channel("accel").lsb(range_g) / np.sqrt(3)
    np.testing.assert_allclose(measured_g.mean(axis=0), GRAVITY_UG * 1e-6, atol=5 * noise_g / np.sqrt(n_samples))
    assert block.temperature_c == pytest.approx((TEMPERATURE_C, TEMPERATURE_C), abs=0.3)


def test_a_capture_larger_than_the_buffer_is_refused(sensor: Opened) -> None:
    """The greeting's capture= is a promise: a count above it must be refused, not overrun the buffer."""
    bring_up(sensor.driver, 2, 1000.0)
    for count in (4097, 0):
        with pytest.raises(InstrumentError, match=r"refused: bad count \(decimal 1\.\.4096\)"):
            sensor.bridge.start_capture(count)
    assert sensor.bridge.start_capture(4096) > 0  # the largest that is allowed (taken whole at 4 kHz above)


def test_a_capture_needs_the_part_measuring(sensor: Opened) -> None:
    """A part in standby makes no samples: the capture is refused at once instead of timing out."""
    sensor.driver.standby()
    with pytest.raises(InstrumentError, match=r"'C 50' refused: capture needs the part measuring"):
        sensor.driver.acquire(50)


def test_a_bridge_that_stalls_reports_the_overflow(sensor: Opened) -> None:
    """The firmware stopped for 50 ms (6 FIFOs' worth at 4 kHz) in the middle of a one-second capture: the
    part's FIFO_OVR must reach the host as `!overflow`, never a block with a hole in it; the next capture is
    whole again. (The 50 ms count from when the process is seen stopped: a process waiting for a CPU takes
    the signal late, and that wait is not the firmware's time.)"""
    bring_up(sensor.driver, 2, 4000.0)
    sensor.bridge.start_capture(4000)
    pid = sensor.firmware.process.pid
    os.kill(pid, signal.SIGSTOP)
    wait_until(lambda: process_state(pid) == "T", "the firmware stopping")
    time.sleep(0.05)  # the stall under test
    os.kill(pid, signal.SIGCONT)
    with pytest.raises(CaptureOverflow, match=r"overflow: FIFO overflowed after \d+ of 4000 samples"):
        sensor.bridge.fetch_capture(0)
    first_sample_index(sensor.driver.acquire(400).codes["accel"], 2)


def test_a_complete_capture_can_be_fetched_again(sensor: Opened) -> None:
    """A reply lost on the line is asked for again: the capture stays until the next C."""
    bring_up(sensor.driver, 2, 4000.0)
    sensor.bridge.start_capture(200)
    first = sensor.bridge.fetch_capture(0)
    give_up = time.monotonic() + DEADLINE_S
    while first[1] is None:  # the end temperature comes only once the capture is complete
        assert time.monotonic() < give_up, f"the 200-sample capture is not complete within {DEADLINE_S} s"
        time.sleep(0.002)
        first = sensor.bridge.fetch_capture(0)
    assert len(first[0]) == 200 * 9
    assert sensor.bridge.fetch_capture(0) == first
    assert sensor.bridge.fetch_capture(150) == (first[0][150 * 9:], first[1])
    assert sensor.bridge.fetch_capture(200) == (b"", first[1])


def test_the_host_can_still_drain_the_fifo_itself(sensor: Opened) -> None:
    """R 11 288 passes through as one burst: the driver's own FIFO draining (version 1, and blocks above the
    buffer) works through the firmware too, partial samples carried and all."""
    bring_up(sensor.driver, 2, 125.0)
    sensor.bridge.capture_capacity_samples = 0  # as a version 1 bridge: the driver drains the FIFO itself
    block = sensor.driver.acquire(100)
    first_sample_index(block.codes["accel"], 2)
    assert block.temperature_c == pytest.approx((TEMPERATURE_C, TEMPERATURE_C), abs=0.3)


def test_a_line_left_unfinished_does_not_spoil_the_next_request(bridge_host: Path) -> None:
    """Half a request from a client that went away (or noise from plugging in) is dropped (as its client goes,
    and in any case after a second), so the next client's greeting is read whole through the project's own line
    port; a byte that is not text is refused, not cut off unseen. (Malformed requests of every kind, against the
    simulator too: tests/firmware/test_bridge_conformance.py.)"""
    with running(bridge_host, clock="monotonic") as firmware:
        stray = os.open(firmware.path, os.O_RDWR | os.O_NOCTTY)
        os.write(stray, b"R 0")
        os.close(stray)
        time.sleep(1.1)  # the partial line's age under test
        port = LinePort.open(firmware.path, "bridge", 921600, 1.0)
        try:
            assert port.ask("?").startswith("ADXL355-BRIDGE 3 part=adxl355 ")
            assert port.ask("R 00 1\x00 4") == "!not printable ASCII"
        finally:
            port.close()


def test_the_fifo_is_not_lent_out_during_a_capture(line: LinePort) -> None:
    """A FIFO burst from the host in the middle of a capture would steal its samples: refused."""
    assert line.ask("W 28 00") == "=" and line.ask("W 2D 00") == "="  # 4000 Hz, measuring
    assert line.ask("C 4000").startswith("=")
    assert line.ask("R 11 9") == "!FIFO_DATA is being captured (fetch with G)"
    assert line.ask("R 00 1") == "=AD"


def test_torn_temperature_reads_never_reach_the_capture(bridge_host: Path) -> None:
    """With a fifth of the model's TEMP2/TEMP1 reads torn, a single read is ~28 °C off now and then; the
    temperatures the firmware reports at each capture's start and end never are."""
    with opened(bridge_host, "--tear-rate", "0.2") as sensor:
        single = [ADXL355.temperature.celsius(adxl355.raw_temperature(*sensor.bridge.read(adxl355.REG_TEMP2, 2)))
                  for _ in range(200)]
        assert sum(abs(t - TEMPERATURE_C) > 20 for t in single) >= 15  # the quirk is there (~40 expected)
        bring_up(sensor.driver, 2, 4000.0)
        for _ in range(10):
            block = sensor.driver.acquire(50)
            assert block.temperature_c == pytest.approx((TEMPERATURE_C, TEMPERATURE_C), abs=0.3)


def test_a_part_whose_temperature_never_agrees_is_refused(bridge_host: Path) -> None:
    """Every read torn: no two reads agree in ten, and the capture says so rather than report a guess."""
    with opened(bridge_host, "--tear-rate", "1") as sensor:
        bring_up(sensor.driver, 2, 1000.0)
        with pytest.raises(InstrumentError, match=r"refused: temperature: TEMP2/TEMP1 did not agree in 10 reads"):
            sensor.bridge.start_capture(100)
