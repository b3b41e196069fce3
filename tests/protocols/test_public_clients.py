"""Independent clients from PyPI, unchanged, against the simulated controllers over loopback TCP: each talks
to the simulator as it would to the chamber it was written for, and what it reads and sets is the simulated
chamber's state."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pytest
import pyvisa
from basil.dut import Dut
from espec_pr3j import EspecPr3j
from espec_pr3j.data_classes import OperationMode
from pymeasure.instruments.thermotron import Thermotron3800

from accelcal_rig.config.load import load_rig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.protocols.chamber_lines import line_protocol
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG


@contextmanager
def simulated(profile: str, **options: object) -> Iterator[tuple[SimulatedLineChamberServer, VirtualLab, int]]:
    lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
    server = SimulatedLineChamberServer(lab, line_protocol(profile), "tcp", **options).start()  # type: ignore[arg-type]
    try:
        yield server, lab, int(server.endpoint.rsplit(":", 1)[1])
    finally:
        server.stop()


def near_air(lab: VirtualLab) -> float:
    """Within the controller's reading noise (and its answer's rounding) of the simulated air."""
    return pytest.approx(lab.thermal.air_c(lab.clock.now()), abs=6 * lab.chamber_noise_c + 0.05)


def test_pymeasure_thermotron3800_drives_the_thermotron_simulator() -> None:
    """PyMeasure's Thermotron3800 (pymeasure/instruments/thermotron/thermotron3800.py) sends IDEN?, PVAR1?,
    SETP1?, `SETP1,%g`, RUNM and STOP, as an 8800 takes them. Quirk: the 3800 class never reads the `0` an
    8800 answers to an operation (its settings are write-only, with a 1 s pause), so that `0` would be read
    as the next query's reply; the test reads it off after each operation, as a 8800 client must. Every
    write sleeps 1 s, hence the test's length."""
    with simulated("thermotron-8800") as (server, lab, port):
        oven = Thermotron3800(f"TCPIP::127.0.0.1::{port}::SOCKET", visa_library="@py", read_termination="\r\n",
                              write_termination="\r", timeout=5000)
        try:
            assert oven.id == server.identity
            assert oven.temperature == near_air(lab)
            oven.setpoint = 31.5
            assert oven.read() == "0"  # what the 3800 class leaves unread
            assert oven.setpoint == pytest.approx(31.5)
            assert lab.thermal.setpoint_c == pytest.approx(31.5)
            oven.stop()
            assert oven.read() == "0"
            assert not lab.thermal.powered
            oven.run()
            assert oven.read() == "0"
            assert lab.thermal.powered
        finally:
            oven.adapter.close()


def test_basil_weiss_labevent_drives_the_simserv_simulator() -> None:
    """basil's weissLabEvent (basil/HL/weiss_labevent.py) checks the chamber type at init with `99997¶1¶1`,
    reads the status as `10012¶1¶1` (knowing only 1, 3, 4 and 8), and starts and stops the manual run with
    digital output 1. Quirks: its socket layer reads one `recv(512)` per reply and decodes ASCII only."""
    with simulated("simserv", identity="LabEvent T/210/70/5") as (server, lab, port):
        dut = Dut({"transfer_layer": [{"name": "Socket", "type": "Socket",
                                       "init": {"address": "127.0.0.1", "port": port, "write_termination": "\r",
                                                "read_termination": "\r\n", "encoding": "ascii"}}],
                   "hw_drivers": [{"name": "chamber", "type": "weiss_labevent", "interface": "Socket"}]})
        dut.init()  # refuses a chamber whose type is not LabEvent T/210/70/5
        try:
            chamber = dut["chamber"]
            assert chamber.get_temperature() == near_air(lab)
            chamber.set_temperature(-20.0)
            assert chamber.get_temperature_setpoint() == pytest.approx(-20.0)
            assert lab.thermal.setpoint_c == pytest.approx(-20.0)
            assert chamber.get_status().startswith("3:")
            chamber.stop_manual_mode()
            assert not lab.thermal.powered and chamber.get_status().startswith("1:")
            chamber.start_manual_mode()
            assert lab.thermal.powered
        finally:
            dut.close()


def test_espec_pr3j_drives_the_espec_simulator() -> None:
    """espec-pr3j (src/espec_pr3j/espec_pr3j.py) over PyVISA: TEMP?, HUMI?, MON?, MODE?, `TEMP, S%.1f` and
    `MODE, <mode>`, each setting checked against the `OK:` echo. Quirk: its reply patterns have no minus
    sign, so it cannot read a negative temperature or limit; the simulated controller's lower limit is put
    at 0 °C for it."""
    with simulated("espec-p300") as (server, lab, port):
        lab.controller_limits_c = (0.0, lab.controller_limits_c[1])
        chamber = EspecPr3j(resource_path=f"TCPIP0::127.0.0.1::{port}::SOCKET",
                            resource_manager=pyvisa.ResourceManager("@py"))
        try:
            status = chamber.get_temperature_status()
            assert status.current_temperature == near_air(lab)
            assert (status.lower_limit, status.upper_limit) == lab.controller_limits_c
            assert chamber.get_humidity_status().current_humidity == pytest.approx(lab.chamber_humidity_pct(), abs=0.5)
            chamber.set_target_temperature(31.0)
            assert lab.thermal.setpoint_c == pytest.approx(31.0)
            assert chamber.get_mode() is OperationMode.CONSTANT
            chamber.set_mode(OperationMode.STANDBY)
            assert chamber.get_mode() is OperationMode.STANDBY and not lab.thermal.powered
            state = chamber.get_test_area_state()
            assert state.operation_state is OperationMode.STANDBY and state.number_of_alarms == 0
            chamber.set_mode(OperationMode.CONSTANT)
            assert lab.thermal.powered
        finally:
            chamber.close()
