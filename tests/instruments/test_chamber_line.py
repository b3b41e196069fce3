"""The line chamber driver against the simulator generated from each profile, over real transports: loopback
TCP (a controller's Ethernet port) and a pseudo-terminal (its serial port)."""

from __future__ import annotations

import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.rig import ChamberConfig, FaultInjection, RetryPolicy
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import AlarmReporting, alarm_active, controller_limits, humidity_pct
from accelcal_rig.instruments.chamber_line import LineChamber
from accelcal_rig.instruments.limits import LimitedChamber
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.faults import ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG


@pytest.fixture
def served():
    """Start a simulated controller of a profile on a transport; yield (driver, server, lab, clock)."""
    started = []

    def start(profile: str, transport: str = "tcp", **options):
        clock = VirtualClock()
        lab = VirtualLab(load_rig(SIM_RIG).model, clock, 0)
        protocol = line_protocol(profile, options.pop("overrides", None))
        server = SimulatedLineChamberServer(lab, protocol, transport, **options).start()
        driver = LineChamber.open(server.endpoint, protocol, timeout_s=0.5)
        started.append((driver, server))
        return driver, server, lab, clock

    yield start
    for driver, server in started:
        driver.close()
        server.stop()


@pytest.mark.parametrize("transport", ["tcp", "pty"])
@pytest.mark.parametrize("profile", sorted(LINE_PROFILES))
def test_each_profile_drives_its_simulated_controller(profile: str, transport: str, served) -> None:
    chamber, server, lab, clock = served(profile, transport)
    assert chamber.endpoint == (f"tcp {server.endpoint}" if transport == "tcp" else f"serial {server.endpoint}")
    assert "simulated chamber" in chamber.identify()
    guarded = LimitedChamber(chamber, ChamberConfig(min_setpoint_c=-55, max_setpoint_c=100))
    guarded.write_setpoint_c(-40.0)  # written, then read back by the gate
    assert server.last_setpoint_c == pytest.approx(-40.0)
    clock.sleep(3600.0)
    assert chamber.read_temperature_c() == pytest.approx(-40.0, abs=0.5)
    assert controller_limits(chamber) == ((-70.0, 180.0) if LINE_PROFILES[profile].read_low_limit else None)
    assert alarm_active(chamber) is False
    assert isinstance(chamber, AlarmReporting) == (LINE_PROFILES[profile].alarm is not None)
    humidity = humidity_pct(chamber)
    assert humidity is not None and 0.0 < humidity <= 100.5


def test_the_controllers_own_limits_refuse_before_the_wire(served) -> None:
    chamber, server, lab, _ = served("simserv")
    lab.controller_limits_c = (-40.0, 120.0)
    guarded = LimitedChamber(chamber, ChamberConfig(min_setpoint_c=-55, max_setpoint_c=100))
    with pytest.raises(InstrumentError, match=r"setpoint -50 °C refused, the controller's own limits are -40…120 °C"):
        guarded.write_setpoint_c(-50.0)
    assert server.last_setpoint_c is None


def test_a_controller_whose_panel_locks_remote_writes_refuses_them_in_one_line(served) -> None:
    """ESPEC's documented refusal for it is `PROTECT ON` (data protection set on the panel)."""
    chamber, server, _, _ = served("espec-p300")
    server.local_mode = True
    with pytest.raises(InstrumentError, match=r"^chamber \(tcp 127\.0\.0\.1:\d+\): 'TEMP, S25.0' refused: "
                                              r"'NA:PROTECT ON' \(the controller's data protection is on"):
        chamber.write_setpoint_c(25.0)
    assert server.last_setpoint_c is None


def test_a_controller_not_in_celsius_is_refused(served) -> None:
    chamber, _, _, _ = served("thermotron-8800", units="F")
    with pytest.raises(InstrumentError, match=r"chamber \(tcp .*\): controller is not in °C \(units read 'F'"):
        chamber.identify()


def test_an_rs485_address_reaches_only_its_controller(served) -> None:
    chamber, server, _, _ = served("espec-p300", "pty", overrides={"request_prefix": "2,"})
    assert chamber.read_setpoint_c() == pytest.approx(23.0)
    other = LineChamber.open(server.endpoint, line_protocol("espec-p300", {"request_prefix": "3,"}), timeout_s=0.2)
    try:
        with pytest.raises(TransientInstrumentError, match="no reply within the timeout"):
            other.read_setpoint_c()  # addressed to controller 3: controller 2 stays silent
    finally:
        other.close()


def test_garbled_and_dropped_replies_are_retried_to_success(served) -> None:
    """A lossy line (a fifth of the replies corrupted or dropped) still reads right, through the retries."""
    clock = VirtualClock()
    lab = VirtualLab(load_rig(SIM_RIG).model, clock, 0)
    faults = ReplyFaults(FaultInjection(rate=0.2, kinds=["corrupt", "drop"], seed=3), "chamber", clock.now)
    protocol = LINE_PROFILES["simserv"]
    server = SimulatedLineChamberServer(lab, protocol, "tcp", faults=faults).start()
    chamber = LineChamber.open(server.endpoint, protocol, timeout_s=0.2)
    try:
        policy = RetryPolicy(attempts=8, first_backoff_s=0.0, max_backoff_s=0.0)
        chamber.retry_exchanges(Retrier(policy, clock, EventLog(clock)).call)
        readings = [chamber.read_temperature_c() for _ in range(30)]
        assert all(abs(r - 23.0) < 1.0 for r in readings)
        assert sum(faults.counts.values()) > 0
    finally:
        chamber.close()
        server.stop()


def test_a_dead_endpoint_is_one_line_naming_it() -> None:
    with pytest.raises(InstrumentError, match=r"chamber \(tcp 127\.0\.0\.1:9\): cannot open"):
        LineChamber.open("127.0.0.1:9", LINE_PROFILES["thermotron-8800"], timeout_s=0.2)
