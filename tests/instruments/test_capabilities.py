"""A driver has a capability exactly when its profile has the feature: each built-in line profile and register
map, and overrides that add or take one away; the helpers answer for a chamber without it."""

from __future__ import annotations

import pytest
from pymodbus.client import ModbusSerialClient

from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.capabilities import (
    AlarmReporting,
    ConstantRateRotation,
    ControllerLimits,
    HumiditySensing,
    Purging,
    Reconnecting,
    SetpointResolution,
    alarm_active,
    controller_limits,
    has_purge,
    humidity_pct,
    set_purge,
    setpoint_decimals,
)
from accelcal_rig.instruments.chamber_line import LineChamber
from accelcal_rig.instruments.chamber_modbus import ModbusChamber
from accelcal_rig.instruments.interfaces import Chamber, Positioning, Turntable
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, line_protocol
from accelcal_rig.protocols.chamber_registers import PROFILES, register_map
from accelcal_rig.protocols.turntable_line import PROTOCOLS, turntable_protocol
from tests.instruments.expected_protocol import expected_protocol

CHAMBER_CAPABILITIES = (AlarmReporting, ControllerLimits, HumiditySensing, Purging, SetpointResolution)


def capabilities(device: object) -> set[type]:
    return {capability for capability in CHAMBER_CAPABILITIES if isinstance(device, capability)}


#: What each built-in line profile's commands offer (docs/instruments.md has the sources).
LINE_EXPECTED = {
    "espec-p300": {AlarmReporting, ControllerLimits, HumiditySensing, SetpointResolution},
    "thermotron-8800": {AlarmReporting, HumiditySensing, SetpointResolution},
    "simserv": {AlarmReporting, ControllerLimits, HumiditySensing, Purging, SetpointResolution},
    "watlow-f4t-scpi": {HumiditySensing, SetpointResolution},
}


@pytest.mark.parametrize("profile", sorted(LINE_PROFILES))
def test_a_line_chamber_has_the_capabilities_of_its_profile_and_no_others(profile: str) -> None:
    with expected_protocol([]) as line:
        chamber = LineChamber(line, "memory", LINE_PROFILES[profile])
        assert capabilities(chamber) == LINE_EXPECTED[profile]
        assert isinstance(chamber, Chamber) and isinstance(chamber, Reconnecting)
        assert type(chamber).__name__ == "LineChamber"  # what a campaign file records as the driver


def test_an_override_that_adds_a_purge_or_takes_the_alarm_away_changes_the_capabilities() -> None:
    purge = {"purge_on": {"send": "PURGE,1", "reply": "0", "answer": "0"},
             "purge_off": {"send": "PURGE,0", "reply": "0", "answer": "0"}}
    with expected_protocol([]) as line:
        with_purge = LineChamber(line, "memory", line_protocol("thermotron-8800", purge))
        without_alarm = LineChamber(line, "memory", line_protocol("thermotron-8800", {"alarm": None}))
        in_full = LineChamber(line, "memory", line_protocol("watlow-f4t-scpi", {
            "write_setpoint": {"send": ":SOURCE:CLOOP1:SPOINT {value}"}}))
    assert isinstance(with_purge, Purging) and has_purge(with_purge)
    assert not isinstance(without_alarm, AlarmReporting) and alarm_active(without_alarm) is False
    assert not isinstance(in_full, SetpointResolution) and setpoint_decimals(in_full) is None


def modbus(profile: str, overrides: dict | None = None) -> ModbusChamber:
    client = ModbusSerialClient("memory", baudrate=9600, timeout=0.05, retries=0)  # never opened
    return ModbusChamber(client, "modbus-rtu memory", register_map(profile, overrides))


def test_a_modbus_chamber_has_the_capabilities_of_its_register_map() -> None:
    assert sorted(PROFILES) == ["watlow-f4", "watlow-f4t"]
    assert capabilities(modbus("watlow-f4")) == {AlarmReporting, ControllerLimits, SetpointResolution}
    assert capabilities(modbus("watlow-f4t")) == {AlarmReporting, ControllerLimits}  # float32: the set point in full
    assert capabilities(modbus("watlow-f4t", {"purge_register": 2010, "alarm_register": None,
                                              "setpoint_low_register": None, "setpoint_high_register": None})) == {Purging}
    assert type(modbus("watlow-f4")).__name__ == "ModbusChamber"
    assert setpoint_decimals(modbus("watlow-f4")) == 1


def test_the_helpers_answer_for_a_chamber_without_the_capability() -> None:
    chamber = modbus("watlow-f4t", {"alarm_register": None, "setpoint_low_register": None,
                                    "setpoint_high_register": None})
    assert controller_limits(chamber) is None and humidity_pct(chamber) is None and not has_purge(chamber)
    assert alarm_active(chamber) is False and setpoint_decimals(chamber) is None
    with pytest.raises(InstrumentError, match=r"chamber \(modbus-rtu memory\): no dry-air purge output"):
        set_purge(chamber, True)


@pytest.mark.parametrize("profile", sorted(PROTOCOLS))
def test_every_turntable_positions_and_turns_at_a_constant_rate_where_its_profile_can(profile: str) -> None:
    with expected_protocol([]) as line:
        table = SerialTurntable(line, "memory", PROTOCOLS[profile], 2)
    assert isinstance(table, Turntable) and isinstance(table, Positioning)
    assert isinstance(table, ConstantRateRotation)  # both built-in profiles have rate commands
    assert type(table).__name__ == "SerialTurntable"


def test_a_profile_without_rate_commands_has_no_rate_mode() -> None:
    positioning_only = turntable_protocol("accelcal-line", {"rotate": None, "hold": None})
    with expected_protocol([]) as line:
        table = SerialTurntable(line, "memory", positioning_only, 2)
    assert isinstance(table, Positioning) and not isinstance(table, ConstantRateRotation)
    assert not hasattr(table, "rotate_at")
