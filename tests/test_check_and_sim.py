"""`rig sim` serves the simulated rig as real endpoints; `rig check` talks to them like to a real rig."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from accelcal_rig.config.load import load_rig
from accelcal_rig.sim.pty_line_server import PtyLineServer
from tests.conftest import REPO, SIM_RIG
from tests.test_cli_serve import DEADLINE_S, first_line

RIG = str(Path(sys.executable).parent / "rig")
#: A line of `rig check`: the instrument, OK or FAILED, then what it answered or why it failed.
CHECK_LINE = re.compile(r"(?P<name>chamber|turntable|sensor \S+) +(?P<status>OK|FAILED) +(?P<text>\S.*)")


def check_lines(stdout: str) -> dict[str, tuple[str, str]]:
    """`rig check`'s instrument lines: name → (status, text); every line but the closing one must be one."""
    lines = stdout.splitlines()
    found = {}
    for line in lines[:-1] if lines and lines[-1].startswith("rig ") else lines:
        match = CHECK_LINE.fullmatch(line)
        assert match, f"not a rig check line: {line!r}"
        found[match["name"]] = (match["status"], match["text"])
    return found


@pytest.fixture(scope="module")
def running_sim():
    process = subprocess.Popen([RIG, "sim", str(SIM_RIG)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    endpoints = json.loads(process.stdout.readline())
    yield endpoints
    process.send_signal(signal.SIGINT)
    process.wait(timeout=20)
    assert process.returncode == 0


def rig_config_for(endpoints: dict, folder: Path, sensor_endpoints: dict[str, str] | None = None) -> Path:
    config = yaml.safe_load(SIM_RIG.read_text())
    config["chamber"]["endpoint"] = f"{endpoints['chamber']['host']}:{endpoints['chamber']['port']}"
    config["turntable"]["endpoint"] = endpoints["turntable"]["device"]
    for sensor in config["fixture"]["sensors"]:
        sensor["endpoint"] = (sensor_endpoints or {}).get(sensor["serial"], endpoints["sensors"][sensor["serial"]]["device"])
    path = folder / "lab.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


def test_rig_sim_prints_its_endpoints_first(running_sim: dict) -> None:
    assert running_sim["chamber"]["host"] == "127.0.0.1" and running_sim["chamber"]["port"] > 0
    assert running_sim["turntable"]["device"].startswith("/dev/pts/")
    assert sorted(running_sim["sensors"]) == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]


def test_rig_check_describes_every_instrument(running_sim: dict, tmp_path: Path) -> None:
    result = subprocess.run([RIG, "check", str(rig_config_for(running_sim, tmp_path))], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    lines = check_lines(result.stdout)
    assert list(lines) == ["chamber", "turntable", "sensor ADX355-A001", "sensor ADX355-A002", "sensor ADX355-A003",
                           "sensor ADX355-A004"]
    assert all(status == "OK" for status, _ in lines.values())
    assert lines["chamber"][1].startswith(f"modbus-tcp 127.0.0.1:{running_sim['chamber']['port']}: float32 controller")
    assert lines["turntable"][1].startswith("serial /dev/pts/") and "angles 0.000 0.000 0.000°" in lines["turntable"][1]
    assert sum("ADXL355 rev 1" in text for name, (_, text) in lines.items() if name.startswith("sensor ")) == 4
    assert result.stdout.splitlines()[-1] == "rig simulated-rig: every instrument answered as configured"


def test_rig_check_names_a_sensor_with_the_wrong_identity_and_checks_the_rest(running_sim: dict,
                                                                              tmp_path: Path) -> None:
    impostor = PtyLineServer(lambda r: "ADXL355-BRIDGE 1 x" if r == "?" else "=AD1DE901").start()  # an ADXL359
    try:
        config = rig_config_for(running_sim, tmp_path, {"ADX355-A003": impostor.path})
        result = subprocess.run([RIG, "check", str(config)], capture_output=True, text=True, timeout=60)
    finally:
        impostor.stop()
    assert result.returncode == 2
    lines = check_lines(result.stdout)
    assert lines["sensor ADX355-A003"] == ("FAILED", f"sensor ADX355-A003 (serial {impostor.path}): identity "
                                                     "AD/1D/E9 is not an ADXL355 (AD/1D/ED)")
    assert [name for name, (status, _) in lines.items() if status == "OK"] == [
        "chamber", "turntable", "sensor ADX355-A001", "sensor ADX355-A002", "sensor ADX355-A004"]
    assert result.stderr.strip() == ("rig: error: rig simulated-rig: 1 of 6 instruments failed the check (sensor "
                                     "ADX355-A003); the others answered as configured")


def test_rig_check_with_dead_ports_says_each_and_every_other_instrument(running_sim: dict, tmp_path: Path) -> None:
    """Bringing up a rig with a dead turntable port and a dead bridge: the chamber and the other sensors are
    checked all the same, each dead port is its own line."""
    config = rig_config_for(running_sim, tmp_path, {"ADX355-A002": "/dev/nonexistent-bridge"})
    rig = yaml.safe_load(config.read_text())
    rig["turntable"]["endpoint"] = "/dev/nonexistent-turntable"
    config.write_text(yaml.safe_dump(rig))
    result = subprocess.run([RIG, "check", str(config)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    lines = check_lines(result.stdout)
    assert len(lines) == 6 and lines["chamber"][0] == "OK"
    assert lines["turntable"] == ("FAILED", "turntable (serial /dev/nonexistent-turntable): cannot open: No such "
                                            "file or directory")  # the system's words once, not pyserial's twice
    assert lines["sensor ADX355-A002"][0] == "FAILED" and lines["sensor ADX355-A002"][1].startswith(
        "sensor bridge (serial /dev/nonexistent-bridge): cannot open")
    assert [lines[f"sensor ADX355-A00{n}"][0] for n in (1, 3, 4)] == ["OK"] * 3
    assert result.stderr.strip() == ("rig: error: rig simulated-rig: 2 of 6 instruments failed the check (turntable, "
                                     "sensor ADX355-A002); the others answered as configured")


def test_rig_check_names_each_instrument_without_an_endpoint(tmp_path: Path) -> None:
    """A rig config written before its ports are known: every instrument is a line pointing at its key."""
    config = yaml.safe_load(SIM_RIG.read_text())
    path = tmp_path / "unwired.yaml"
    path.write_text(yaml.safe_dump(config))
    result = subprocess.run([RIG, "check", str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    lines = check_lines(result.stdout)
    assert all(status == "FAILED" and "endpoint: no endpoint given" in text for status, text in lines.values())
    assert len(lines) == 6 and "6 of 6 instruments failed" in result.stderr


def test_the_example_lab_config_is_valid() -> None:
    rig = load_rig(REPO / "configs" / "example-lab.yaml").model
    assert rig.chamber.driver == "modbus-rtu" and rig.chamber.register_map().encoding == "scaled-int16"
    assert rig.turntable.line_protocol().write_terminator == "\r\n"


def chamber_only(folder: Path, endpoint: str | None = None) -> Path:
    """A rig config a technician writes to bring up a new chamber: no turntable, no fixture."""
    config = yaml.safe_load(SIM_RIG.read_text())
    del config["turntable"], config["fixture"]
    if endpoint is not None:
        config["chamber"]["endpoint"] = endpoint
    path = folder / "chamber-only.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


def test_rig_check_of_the_chamber_alone(running_sim: dict, tmp_path: Path) -> None:
    endpoint = f"{running_sim['chamber']['host']}:{running_sim['chamber']['port']}"
    result = subprocess.run([RIG, "check", str(chamber_only(tmp_path, endpoint)), "--only", "chamber"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert len(lines) == 2 and lines[0].startswith(f"chamber  OK      modbus-tcp {endpoint}: float32 controller")
    assert lines[1] == "rig simulated-rig: the chamber answered as configured (only those checked)"


@pytest.mark.parametrize(("argv", "message"), [
    ([], "turntable: required, and missing"),                                 # a campaign's check needs all of it
    (["--only", "turntable"], "turntable: missing, and --only checks it"),
])
def test_a_rig_config_without_an_instrument_is_refused_where_it_is_needed(tmp_path: Path, argv: list[str],
                                                                        message: str) -> None:
    result = subprocess.run([RIG, "check", str(chamber_only(tmp_path)), "--dry-run", *argv], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 2 and message in result.stderr and len(result.stderr.strip().splitlines()) == 1


def test_a_dry_run_check_of_the_sensors_alone(tmp_path: Path) -> None:
    config = yaml.safe_load(SIM_RIG.read_text())
    del config["turntable"]
    (tmp_path / "sensors.yaml").write_text(yaml.safe_dump(config))
    result = subprocess.run([RIG, "check", str(tmp_path / "sensors.yaml"), "--dry-run", "--only", "sensors"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    lines = check_lines(result.stdout)
    assert list(lines) == [f"sensor ADX355-A00{n}" for n in range(1, 5)]


def test_rig_check_of_a_line_chamber_says_what_frost_settings_can_count_on(tmp_path: Path) -> None:
    """A new SIMSERV chamber on the network: identity, both limits, its humidity and dew point, its purge."""
    process = subprocess.Popen([RIG, "sim", str(SIM_RIG), "--chamber-profile", "simserv"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        chamber = json.loads(process.stdout.readline())["chamber"]  # type: ignore[union-attr]
        rig = tmp_path / "new-chamber.yaml"
        rig.write_text(yaml.safe_dump({"name": "bring-up", "chamber": {
            "driver": "line", "profile": "simserv", "endpoint": f"{chamber['host']}:{chamber['port']}"}}))
        result = subprocess.run([RIG, "check", str(rig), "--only", "chamber"], capture_output=True, text=True,
                                timeout=60)
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=20)
    assert result.returncode == 0, result.stderr
    line = result.stdout.splitlines()[0]
    assert line.startswith(f"chamber  OK      tcp {chamber['host']}:{chamber['port']}: accelcal-rig simulated simserv")
    assert "the rig's -55…100 °C, the controller's -70…180 °C" in line
    assert "% RH (dew point 12.0 °C); dry-air purge output" in line


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT], ids=["sigterm", "ctrl-c"])
def test_rig_sim_says_which_simulators_it_stopped_and_exits_0(stop: signal.Signals) -> None:
    process = subprocess.Popen([RIG, "sim", str(SIM_RIG)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        endpoints = json.loads(first_line(process, DEADLINE_S))  # serving from here on
        process.send_signal(stop)
        _, err = process.communicate(timeout=DEADLINE_S)
    finally:
        process.kill()
    assert process.returncode == 0, err.decode()
    assert err.decode().strip().splitlines()[-1] == (
        f"rig sim: stopped (simulators of {SIM_RIG} closed: chamber {endpoints['chamber']['endpoint']}, "
        f"turntable {endpoints['turntable']['device']}, 4 sensor bridges)")
