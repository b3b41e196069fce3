"""An ESPEC P300's settings beyond the lab's physics, as its panel and its remote commands hold them: humidity
control, refrigeration, time signals (relays), key protection, the SRQ mask, network settings. What each
answer looks like is from ESPEC's ChamberConnectLibrary's parsers (`p300.py`) and syndesi's SH-242 driver
(docs/instruments.md); where only a parser shows a format, the format is the one it reads."""

from __future__ import annotations

from dataclasses import dataclass, field

#: `ROM?` and `ROM?,DISP`: the controller's and its display's ROM versions. Only their shape is documented:
#: ChamberConnectLibrary (espec.py process_controller) takes a version starting `P3` as a P300, any other as
#: an SCP-220; syndesi's SH-242 driver takes 9 to 20 characters as a chamber present.
ROM_VERSION = "P300 simulated"
DISPLAY_ROM_VERSION = "P300-DISP simulated"

#: The humidity a P300 takes for its set point and limits, % RH (the profile's `HUMI?` limits; inferred).
HUMIDITY_RANGE_PCT = (0.0, 100.0)

#: `CONSTANT SET?,REF` per refrigeration setting `REF<n>` (p300.py reflookup: REF0 off, REF1 / 3 / 6 manual
#: at 20 / 50 / 100 % capacity, REF9 automatic; syndesi: 0-8 manual, 9 auto): a capacity or a mode word.
REFRIGERATION_ANSWERS = {0: "OFF", 1: "20", 3: "50", 6: "100", 9: "AUTO"}
AUTOMATIC_REFRIGERATION = 9

#: Time signals (relays) 1-12 (p300.py read_relay; ChamberConnectLibrary's Espec class: 12 events).
RELAYS = range(1, 13)


@dataclass
class HumidityControl:
    """The constant humidity set point, whether humidity is controlled, and its alarm limits. The simulated
    chamber has no humidifier: its air's humidity is the room's moisture (sim/moisture.py) whatever is set."""

    setpoint_pct: float = 0.0
    on: bool = False
    low_pct: float = HUMIDITY_RANGE_PCT[0]
    high_pct: float = HUMIDITY_RANGE_PCT[1]

    def setpoint_field(self) -> str:
        """`HUMI?`'s second field: the set point, or OFF where humidity is not controlled."""
        return f"{self.setpoint_pct:.0f}" if self.on else "OFF"


@dataclass
class EspecSettings:
    humidity: HumidityControl = field(default_factory=HumidityControl)
    refrigeration: int = AUTOMATIC_REFRIGERATION
    relays_on: set[int] = field(default_factory=set)
    key_protection: bool = False
    #: The SRQ mask, 8 characters `0<alarm><single step done><state change>00<GPIB>0` (p300.py write_mask).
    srq_mask: str = "00000000"
    #: Address, mask and gateway (`IPSET?`), held only: the simulator's listener stays where it is.
    network: tuple[str, str, str] = ("127.0.0.1", "255.0.0.0", "0.0.0.0")

    def refrigeration_answer(self) -> str:
        return REFRIGERATION_ANSWERS.get(self.refrigeration, str(self.refrigeration))


def counted(numbers: set[int] | list[int]) -> str:
    """`<count>[,<n>…]`, as `ALARM?`, `RELAY?`, `TIMER ON?` and `PRGM USE?,RAM` answer (the libraries read
    the numbers after the first field; syndesi: "N, 1, 2, 5 … N the number")."""
    ordered = sorted(numbers)
    return ",".join(str(n) for n in [len(ordered), *ordered])
