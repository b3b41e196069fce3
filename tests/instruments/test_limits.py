import re

import numpy as np
import pytest

from accelcal_rig.config.load import load_rig
from accelcal_rig.config.rig import ChamberConfig, TurntableAxis, TurntableConfig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.chamber_line import LineChamber
from accelcal_rig.instruments.chamber_modbus import ModbusChamber
from accelcal_rig.instruments.limits import LimitedChamber, LimitedTurntable
from accelcal_rig.protocols.chamber_lines import line_protocol
from accelcal_rig.protocols.chamber_registers import register_map
from accelcal_rig.sim.chamber_line_server import SimulatedLineChamberServer
from accelcal_rig.sim.chamber_server import SimulatedChamberServer
from accelcal_rig.sim.lab import VirtualLab
from tests.conftest import SIM_RIG


class RecordingChamber:
    endpoint = "test-chamber"

    def __init__(self, readback_offset_c: float = 0.0, controller_limits_c: tuple[float, float] | None = None) -> None:
        self.writes: list[float] = []
        self._offset = readback_offset_c
        self._controller = controller_limits_c

    def controller_limits_c(self) -> tuple[float, float] | None:
        return self._controller

    def write_setpoint_c(self, setpoint_c: float) -> None:
        self.writes.append(setpoint_c)

    def read_setpoint_c(self) -> float:
        return self.writes[-1] + self._offset


class RecordingTurntable:
    endpoint = "test-table"

    def __init__(self) -> None:
        self.moves: list[np.ndarray] = []

    def move_to(self, angles_deg: np.ndarray) -> None:
        self.moves.append(angles_deg)


def test_out_of_limit_setpoint_is_refused_before_anything_is_written() -> None:
    inner = RecordingChamber()
    chamber = LimitedChamber(inner, ChamberConfig(min_setpoint_c=-40, max_setpoint_c=85, safe_setpoint_c=20))
    with pytest.raises(InstrumentError, match=r"test-chamber.*-50 °C refused, limits are -40…85"):
        chamber.write_setpoint_c(-50)
    assert inner.writes == []
    chamber.write_setpoint_c(85)
    assert inner.writes == [85]


def test_setpoint_that_does_not_read_back_is_an_error() -> None:
    chamber = LimitedChamber(RecordingChamber(readback_offset_c=0.5), ChamberConfig())
    with pytest.raises(InstrumentError, match=r"^chamber \(test-chamber\): set point 10 °C written, the controller "
                                              r"holds 10.5 °C \(it clamped or refused it\)$"):
        chamber.write_setpoint_c(10)


def test_turntable_limits_apply_to_limited_axes_only() -> None:
    config = TurntableConfig(axes=[
        TurntableAxis(name="tilt", axis=(1, 0, 0), min_deg=-90, max_deg=90),
        TurntableAxis(name="spin", axis=(0, 0, 1), min_deg=-180, max_deg=180, continuous=True),
    ])
    inner = RecordingTurntable()
    table = LimitedTurntable(inner, config)
    table.move_to(np.array([45.0, 700.0]))
    with pytest.raises(InstrumentError, match="axis tilt to 95° refused"):
        table.move_to(np.array([95.0, 0.0]))
    with pytest.raises(InstrumentError, match="3 angles for 2 axes"):
        table.move_to(np.array([0.0, 0.0, 0.0]))
    assert len(inner.moves) == 1


def test_the_controllers_own_limits_refuse_too() -> None:
    raw = RecordingChamber(controller_limits_c=(-20.0, 50.0))
    chamber = LimitedChamber(raw, ChamberConfig(min_setpoint_c=-40, max_setpoint_c=85, safe_setpoint_c=20))
    with pytest.raises(InstrumentError, match=r"setpoint 60 °C refused, the controller's own limits are -20…50 °C"):
        chamber.write_setpoint_c(60)
    chamber.write_setpoint_c(50)
    assert raw.writes == [50]


class TenthsChamber(RecordingChamber):
    """A controller that holds its set point to 0.1 °C (a scaled register, a `{value:.1f}` template)."""

    setpoint_decimals = 1

    def read_setpoint_c(self) -> float:
        return float(f"{self.writes[-1]:.1f}")


def test_a_set_point_is_rounded_to_what_the_controller_holds_before_the_limits_and_the_readback() -> None:
    inner = TenthsChamber()
    chamber = LimitedChamber(inner, ChamberConfig(min_setpoint_c=-40, max_setpoint_c=85, safe_setpoint_c=20))
    chamber.write_setpoint_c(20.749)  # a software ramp's value: written, and read back, as 20.7
    chamber.write_setpoint_c(85.04)   # rounds to the limit itself: allowed
    assert inner.writes == [20.7, 85.0]
    with pytest.raises(InstrumentError, match=r"setpoint 85.1 °C refused, limits are -40…85"):
        chamber.write_setpoint_c(85.06)  # what would go on the wire is beyond the limit
    assert inner.writes == [20.7, 85.0]


def test_a_setpoint_or_angle_that_is_no_number_is_refused_by_name_even_on_a_continuous_axis() -> None:
    inner = RecordingChamber()
    with pytest.raises(InstrumentError, match=r"^chamber \(test-chamber\): setpoint nan °C refused: not a finite "
                                              r"number"):
        LimitedChamber(inner, ChamberConfig()).write_setpoint_c(float("nan"))
    assert inner.writes == []
    table = RecordingTurntable()
    axes = [TurntableAxis(name="spin", axis=(0, 0, 1), continuous=True, min_deg=-180, max_deg=180)]
    limited = LimitedTurntable(table, TurntableConfig(axes=axes))
    with pytest.raises(InstrumentError, match=r"^turntable \(test-table\): axis spin to nan° refused: not a finite"):
        limited.move_to(np.array([np.nan]))  # a continuous axis goes anywhere, but not to NaN
    assert table.moves == []


def _clamping_simulators():
    """Each simulator that acknowledges a set point beyond its controller's limits and clamps it, with a driver
    of it: (driver, simulated lab, stop)."""
    def modbus():
        lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
        server = SimulatedChamberServer(lab, register_map("watlow-f4")).start()
        return ModbusChamber.tcp(server.host, server.port, register_map("watlow-f4")), lab, server.stop

    def simserv():
        lab = VirtualLab(load_rig(SIM_RIG).model, VirtualClock(), 0)
        server = SimulatedLineChamberServer(lab, line_protocol("simserv")).start()
        return LineChamber.open(server.endpoint, line_protocol("simserv"), timeout_s=2.0), lab, server.stop

    return {"modbus watlow-f4": modbus, "line simserv": simserv}


@pytest.mark.parametrize("simulator", ["modbus watlow-f4", "line simserv"])
def test_a_set_point_the_controller_clamps_is_read_back_and_said_in_one_line(simulator: str) -> None:
    """The rig's limits are wider than the controller's, and the controller's own are not checked first (as
    with a profile or map that exposes none): the simulator acknowledges the write and clamps it, and the
    read-back says so, naming the chamber, what was written and what the controller holds."""
    chamber, lab, stop = _clamping_simulators()[simulator]()
    try:
        low, high = lab.controller_limits_c
        beyond = high + 20.0
        guarded = LimitedChamber(chamber, ChamberConfig(min_setpoint_c=low, max_setpoint_c=beyond))
        guarded.controller_limits = None  # what a profile without limit commands leaves the gate
        with pytest.raises(InstrumentError, match=rf"^chamber \({re.escape(chamber.endpoint)}\): set point "
                                                  rf"{beyond:g} °C written, the controller holds {high:g} °C "
                                                  r"\(it clamped or refused it\)$"):
            guarded.write_setpoint_c(beyond)
        assert lab.thermal.setpoint_c == pytest.approx(high)
    finally:
        chamber.close()
        stop()
