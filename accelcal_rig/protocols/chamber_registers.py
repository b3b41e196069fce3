"""Chamber controller register maps as data, with built-in profiles (facts: docs/instruments.md).

Addresses are zero-based Modbus PDU addresses (what goes on the wire), not "4xxxx" numbers.
"""

from __future__ import annotations

import struct
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field


class ChamberRegisterMap(BaseModel):
    """Where a controller keeps each value, and how it encodes temperatures.

    `scaled-int16`: one signed register, value × 10^decimals (the decimals either fixed by `decimals` or
    read from `decimals_register`). `float32`: IEEE-754 in two registers, `word_order` of the two words.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    encoding: Literal["scaled-int16", "float32"]
    word_order: Literal["little", "big"] = "little"
    process_value: int = Field(ge=0, le=65535)
    setpoint: int = Field(ge=0, le=65535)
    decimals: int = Field(1, ge=0, le=3, description="scaled-int16: implied decimal places expected")
    decimals_register: int | None = Field(None, ge=0, le=65535, description="checked against `decimals`")
    units_register: int | None = Field(None, ge=0, le=65535)
    units_celsius: int = Field(1, ge=0, le=65535, description="value of `units_register` that means °C")
    identity_register: int | None = Field(None, ge=0, le=65535)
    identity_value: int | None = Field(None, ge=0, le=65535)
    power_register: int | None = Field(None, ge=0, le=65535, description="event output that runs the chamber")
    power_on: int = Field(1, ge=0, le=65535)
    power_off: int = Field(0, ge=0, le=65535)
    alarm_register: int | None = Field(None, ge=0, le=65535)
    alarm_inactive: list[Annotated[int, Field(ge=0, le=65535)]] = Field([0], max_length=64)
    setpoint_low_register: int | None = Field(None, ge=0, le=65535, description="the controller's own set point "
                                              "limits, encoded like the set point")
    setpoint_high_register: int | None = Field(None, ge=0, le=65535)
    purge_register: int | None = Field(None, ge=0, le=65535, description="event output wired to the chamber's "
                                       "dry-air purge (chamber-specific: none in the built-in maps)")
    purge_on: int = Field(1, ge=0, le=65535)
    purge_off: int = Field(0, ge=0, le=65535)


#: Watlow F4 (TestEquity, Thermotron, Cincinnati Sub-Zero): signed 16-bit, decimals from register 606,
#: units at 901 (1 = °C), model code 5270 at 0, event 1 (chamber power) at 2000, alarm 1 at 102, input 1's
#: set point low / high limits at 602 / 603.
WATLOW_F4 = ChamberRegisterMap(
    encoding="scaled-int16", process_value=100, setpoint=300, decimals=1, decimals_register=606,
    units_register=901, units_celsius=1, identity_register=0, identity_value=5270,
    power_register=2000, power_on=1, power_off=0, alarm_register=102, alarm_inactive=[0],
    setpoint_low_register=602, setpoint_high_register=603,
)

#: Watlow F4T (Data Map 1): float32, low word first by default; set point 2782, process value 2820;
#: event 1 "Power" at 16594 (63 on, 62 off); alarm 1 state at 1356 (88, 61 and 12 inactive); loop 1's set
#: point low / high limits at 2774 / 2776 (ESPEC's ChamberConnectLibrary, watlowf4t.py get_loop_range and
#: set_loop_range). It has no identity or units register in its map, so only the values' plausibility
#: identifies it.
WATLOW_F4T = ChamberRegisterMap(
    encoding="float32", word_order="little", process_value=2820, setpoint=2782,
    power_register=16594, power_on=63, power_off=62, alarm_register=1356, alarm_inactive=[88, 61, 12],
    setpoint_low_register=2774, setpoint_high_register=2776,
)

def encode_temperature(m: ChamberRegisterMap, temperature_c: float) -> list[int]:
    """A temperature in the map's encoding: a float's two words in its order, or a scaled signed register."""
    if m.encoding == "float32":
        high, low = struct.unpack(">HH", struct.pack(">f", temperature_c))
        return [low, high] if m.word_order == "little" else [high, low]
    return [int(round(temperature_c * 10**m.decimals)) & 0xFFFF]


PROFILES: dict[str, ChamberRegisterMap] = {"watlow-f4": WATLOW_F4, "watlow-f4t": WATLOW_F4T}


def register_map(profile: str, overrides: dict[str, object] | None = None) -> ChamberRegisterMap:
    """A built-in profile, with any fields the rig config overrides (validated)."""
    return ChamberRegisterMap.model_validate({**PROFILES[profile].model_dump(), **(overrides or {})})
