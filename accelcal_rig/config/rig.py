"""The rig config: what the rig is (chamber, turntable kinematics, fixture of DUTs, simulated physics)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BeforeValidator, Field, ValidationError, field_validator, model_validator

from accelcal_rig.config.bounds import (
    AngleDeg,
    Baudrate,
    Real,
    StrictModel,
    TemperatureC,
    TimeoutS,
    Whole,
    whole_number,
)
from accelcal_rig.config.lab import ONE_LINE, InstrumentIdentity, IsoDate, LabConfig, References
from accelcal_rig.core.identifiers import SERIAL_PATTERN
from accelcal_rig.core.thermal import dut_time_constant_s
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2, site_gravity_g
from accelcal_rig.parts.registry import DEFAULT_PART, part
from accelcal_rig.plugins import Kind, driver_problem
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES, ChamberLineProtocol, line_protocol
from accelcal_rig.protocols.chamber_registers import PROFILES as REGISTER_PROFILES
from accelcal_rig.protocols.chamber_registers import ChamberRegisterMap, register_map
from accelcal_rig.protocols.turntable_line import TurntableProtocol, turntable_protocol

#: A year of campaign time, in minutes: the furthest a simulated fault may be scheduled.
_YEAR_MIN = 365 * 24 * 60.0



def _known_driver(kind: Kind) -> classmethod:
    """A validator of a `driver:` name against the registered drivers of `kind`."""
    def check(cls: type, value: str) -> str:
        problem = driver_problem(kind, value)
        if problem:
            raise ValueError(problem)
        return value
    return field_validator("driver")(classmethod(check))  # type: ignore[return-value]


#: Every built-in chamber profile: Modbus register maps and ASCII line protocols.
ChamberProfile = Literal["watlow-f4", "watlow-f4t", "espec-p300", "thermotron-8800", "simserv", "watlow-f4t-scpi"]


class ChamberConfig(InstrumentIdentity):
    """Thermal chamber: what it is (make, model, serial), how to reach its controller, its register map, limits
    and dynamics."""

    driver: str = Field("modbus-tcp", max_length=64, description="a chamber driver (accelcal_rig.plugins)")
    _driver = _known_driver("chamber")
    #: Settings of a plug-in driver, which validates them itself.
    options: dict[str, Any] = Field({}, description="settings a plug-in chamber driver reads")
    endpoint: str | None = Field(None, max_length=1024, description="modbus-tcp: host:port; modbus-rtu: serial "
                                 "device or URL; line: host:port (TCP) or a serial device or URL")
    device_id: Whole = Field(1, ge=0, le=247)
    profile: ChamberProfile = Field("watlow-f4t", description="register map (modbus drivers) or line protocol "
                                    "(line driver)")
    registers: dict[str, Any] = Field({}, description="fields of the profile's register map to override")
    protocol_overrides: dict[str, Any] = Field({}, description="fields of the profile's line protocol to override")
    timeout_s: TimeoutS = 1.0
    baudrate: Baudrate = 9600
    parity: Literal["N", "E", "O"] = "N"
    stopbits: Annotated[Literal[1, 2], BeforeValidator(whole_number)] = 1
    min_setpoint_c: TemperatureC = -55.0
    max_setpoint_c: TemperatureC = 100.0
    safe_setpoint_c: TemperatureC = 23.0
    ramp_rate_c_per_min: Real = Field(3.0, ge=0.1, le=50)
    dew_point_c: TemperatureC | None = Field(None, description="the chamber air's dew point to assume (used "
                                             "instead of any humidity reading: a temperature-only chamber, or a "
                                             "conservative value); a procedure's frost check needs this or a "
                                             "humidity reading")

    def register_map(self) -> ChamberRegisterMap:
        return register_map(self.profile, self.registers)

    def line_protocol(self) -> ChamberLineProtocol:
        return line_protocol(self.profile, self.protocol_overrides)

    @model_validator(mode="after")
    def _consistent(self) -> ChamberConfig:
        if self.driver in ("modbus-tcp", "modbus-rtu"):
            if self.profile not in REGISTER_PROFILES:
                raise ValueError(f"profile {self.profile} is a line protocol: use driver: line "
                                 f"(register maps: {', '.join(REGISTER_PROFILES)})")
            _first_error_as_value_error("registers", self.register_map)
        if self.driver == "line":
            if self.profile not in LINE_PROFILES:
                raise ValueError(f"profile {self.profile} is a Modbus register map: use driver: modbus-tcp or "
                                 f"modbus-rtu (line protocols: {', '.join(LINE_PROFILES)})")
            _first_error_as_value_error("protocol_overrides", self.line_protocol)
        if self.driver == "modbus-tcp" and self.endpoint and not is_host_port(self.endpoint):
            raise ValueError(f"modbus-tcp endpoint {self.endpoint!r} is not host:port")
        if self.min_setpoint_c >= self.max_setpoint_c:
            raise ValueError("min_setpoint_c must be below max_setpoint_c")
        if not self.min_setpoint_c <= self.safe_setpoint_c <= self.max_setpoint_c:
            raise ValueError("safe_setpoint_c must lie within the setpoint limits")
        return self


class TurntableAxis(StrictModel):
    """One rotary axis of the kinematic chain, its direction given in its parent's frame at zero angles."""

    name: str = Field(min_length=1, max_length=32, pattern=r"^[A-Za-z0-9_.-]+$")
    axis: tuple[Annotated[Real, Field(ge=-1e6, le=1e6)], Annotated[Real, Field(ge=-1e6, le=1e6)],
                Annotated[Real, Field(ge=-1e6, le=1e6)]]
    min_deg: AngleDeg = -180.0
    max_deg: AngleDeg = 180.0
    continuous: bool = Field(False, description="endless axis: angles wrap into [min_deg, max_deg)")
    speed_deg_s: Real = Field(10.0, ge=0.01, le=1000)
    max_rate_dps: Real | None = Field(None, gt=0, le=10000, description="rate mode: the highest rate (°/s, "
                                      "either direction) the axis may be commanded; None: the axis has no rate mode")
    max_acceleration_dps2: Real | None = Field(None, gt=0, le=100000, description="rate mode: the highest "
                                               "acceleration limit (°/s²) a rate may be commanded with")
    slip_ring: bool = Field(False, description="the axis turns endlessly without winding a cable (a slip ring): "
                            "constant-rate rotation needs one; default: true for a continuous axis")

    @model_validator(mode="before")
    @classmethod
    def _slip_ring_of_a_continuous_axis(cls, data: Any) -> Any:
        if isinstance(data, dict) and "slip_ring" not in data:
            return {**data, "slip_ring": bool(data.get("continuous", False))}
        return data

    @field_validator("axis")
    @classmethod
    def _nonzero(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        norm = float(np.linalg.norm(value))
        if norm < 1e-9:
            raise ValueError("axis direction must not be zero")
        return tuple(float(v) / norm for v in value)  # type: ignore[return-value]

    @model_validator(mode="after")
    def _limits(self) -> TurntableAxis:
        if self.min_deg >= self.max_deg:
            raise ValueError("min_deg must be below max_deg")
        if self.continuous and self.max_deg - self.min_deg != 360.0:
            raise ValueError("a continuous axis wraps over exactly 360°: set max_deg = min_deg + 360")
        if (self.max_rate_dps is None) != (self.max_acceleration_dps2 is None):
            raise ValueError("rate mode needs both max_rate_dps and max_acceleration_dps2 (or neither)")
        return self

    @property
    def has_rate_mode(self) -> bool:
        """Whether the rig config gives the axis rate and acceleration limits (constant-rate rotation)."""
        return self.max_rate_dps is not None and self.max_acceleration_dps2 is not None

    def allows(self, angle_deg: float) -> bool:
        """The one axis-limit rule: a continuous axis goes anywhere, any other stays within its limits."""
        return self.continuous or self.min_deg <= angle_deg <= self.max_deg


class TurntableConfig(InstrumentIdentity):
    """What the table is (make, model, serial) and its chain of rotary axes, outermost first; the fixture sits on
    the innermost axis."""

    driver: str = Field("serial", max_length=64, description="a turntable driver (accelcal_rig.plugins)")
    _driver = _known_driver("turntable")
    endpoint: str | None = Field(None, max_length=1024, description="serial device or pyserial URL "
                                 "(socket://host:port, …)")
    baudrate: Baudrate = 9600
    protocol: Literal["accelcal-line", "acutrol3000"] = "accelcal-line"
    protocol_overrides: dict[str, Any] = Field({}, description="fields of the line protocol to override")
    timeout_s: TimeoutS = 2.0
    axes: list[TurntableAxis] = Field(min_length=1, max_length=6)
    position_tolerance_deg: Real = Field(0.01, ge=1e-6, le=5)
    accuracy_arcsec: Real = Field(3.0, ge=0, le=3600, description="angular position accuracy of each axis "
                                  "(spec sheet, ±): the fit's reference-mode uncertainty, the simulated table's error")
    rate_accuracy_pct: Real | None = Field(None, ge=0, le=10, description="rate mode: accuracy of a constant "
                                           "rate (spec sheet, ± % of the rate): the simulated table's rate offset")
    rate_stability_pct: Real | None = Field(None, ge=0, le=10, description="rate mode: stability of a constant "
                                            "rate (spec sheet, % of the rate, 1σ): the simulated rate's wobble")

    @field_validator("axes")
    @classmethod
    def _unique_names(cls, value: list[TurntableAxis]) -> list[TurntableAxis]:
        names = [a.name for a in value]
        if len(set(names)) != len(names):
            raise ValueError("axis names must be distinct")
        return value

    def line_protocol(self) -> TurntableProtocol:
        return turntable_protocol(self.protocol, self.protocol_overrides)

    @model_validator(mode="after")
    def _valid_protocol(self) -> TurntableConfig:
        _first_error_as_value_error("protocol_overrides", self.line_protocol)
        return self


class SensorConfig(StrictModel):
    """One DUT on the fixture. `mount_euler_deg`: rotation of the DUT frame in the fixture frame (xyz)."""

    serial: str = Field(min_length=1, max_length=64, pattern=SERIAL_PATTERN)
    name: str = Field("", max_length=64)
    part: str = Field(DEFAULT_PART, max_length=64, description="the sensor part (accelcal_rig.parts), e.g. adxl357")
    driver: str = Field("serial-bridge", max_length=64, description="a sensor driver (accelcal_rig.plugins)")
    _driver = _known_driver("sensor")
    endpoint: str | None = Field(None, max_length=1024, description="serial-bridge: device or URL; spidev: "
                                 "bus.chip_select")
    baudrate: Baudrate = 921600
    spi_speed_hz: Whole = Field(5_000_000, ge=1000, le=10_000_000)
    timeout_s: TimeoutS = 1.0
    mount_euler_deg: tuple[AngleDeg, AngleDeg, AngleDeg] = (0.0, 0.0, 0.0)
    customer: str = Field("", max_length=200, pattern=ONE_LINE, description="whose item it is (its certificate states "
                          "it); empty: rig run --customer's, else not stated")
    contact: str = Field("", max_length=200, pattern=ONE_LINE, description="the customer's contact for this item "
                         "(a person, an address: its certificate states it); empty: rig run --contact's, else not stated")
    received_date: IsoDate | None = Field(None, description="when the laboratory received the item (YYYY-MM-DD); "
                                          "unset: rig run --received's, else not stated")
    lot: str = Field("", max_length=64, pattern=ONE_LINE, description="the lab's lot this DUT belongs to (its own word "
                     "for it: a production or incoming lot, not the part number); empty: rig run --lot's, else none")
    condition: str = Field("", max_length=500, pattern=ONE_LINE, description="the item's condition on receipt (e.g. "
                           "'no visible damage'); empty: rig run --condition's, else not stated")

    @field_validator("part")
    @classmethod
    def _known_part(cls, value: str) -> str:
        try:
            part(value)
        except KeyError as exc:
            raise ValueError(exc.args[0]) from None
        return value


def _first_error_as_value_error(key: str, build: Callable[[], object]) -> None:
    """Build a nested model from overrides; report its first problem under `key` in the config's error."""
    try:
        build()
    except ValidationError as exc:
        first = exc.errors(include_url=False)[0]
        raise ValueError(f"{key}.{'.'.join(map(str, first['loc']))}: {first['msg']}") from None


def is_host_port(endpoint: str) -> bool:
    """`host:port` (a TCP endpoint), not a device path or a URL."""
    host, _, port = endpoint.rpartition(":")
    return bool(host) and "/" not in host and port.isdigit() and 0 < int(port) < 65536


class FixtureConfig(StrictModel):
    sensors: list[SensorConfig] = Field(min_length=1, max_length=64)

    @field_validator("sensors")
    @classmethod
    def _unique_serials(cls, value: list[SensorConfig]) -> list[SensorConfig]:
        seen: dict[str, str] = {}
        for sensor in value:  # compared as a person reads them: ADX-a1 and ADX-A1 are one item's label
            other = seen.setdefault(sensor.serial.casefold(), sensor.serial)
            if other != sensor.serial or sum(s.serial == other for s in value) > 1:
                raise ValueError(f"sensor serial numbers must be distinct, case aside: {other!r} and "
                                 f"{sensor.serial!r}" if other != sensor.serial else
                                 f"sensor serial numbers must be distinct: {other!r} twice")
        return value


class FaultInjection(StrictModel):
    """Faults the simulators inject (dry runs and `rig sim`), to prove the engine survives them.

    Transient faults hit each reply with probability `rate`, the kind drawn from `kinds`; persistent ones
    switch on after a time on the campaign's clock (None: never).
    """

    rate: Real = Field(0.0, ge=0, le=1, description="share of replies hit by a transient fault")
    kinds: list[Literal["drop", "delay", "corrupt", "disconnect", "busy"]] = ["drop", "delay", "corrupt", "disconnect"]
    delay_s: Real = Field(0.05, ge=0, le=10, description="wall-clock delay of a delayed reply")
    disconnect_s: Real = Field(2.0, ge=0, le=3600, description="campaign time a disconnected line stays dead")
    seed: Whole = Field(0, ge=0, le=2**32 - 1)
    chamber_stall_after_min: Real | None = Field(None, ge=0, le=_YEAR_MIN,
                                                 description="the chamber stops following its setpoint")
    turntable_stall_after_min: Real | None = Field(None, ge=0, le=_YEAR_MIN, description="the turntable stops moving")
    sensor_wrong_id: str | None = Field(None, max_length=64, description="serial of a DUT whose part ID reads wrong")
    sensor_stuck: str | None = Field(None, max_length=64, description="serial of a DUT whose samples freeze")
    sensor_stuck_after_min: Real = Field(0.0, ge=0, le=_YEAR_MIN, description="when that DUT's samples freeze")
    sensor_loose: str | None = Field(None, max_length=64, description="serial of a DUT loose on its mount: turned "
                                     "a little, at random, at every pose")
    sensor_loose_deg: Real = Field(3.0, ge=0, le=90, description="the RMS angle of that DUT's turn at each pose")
    sensor_misoriented: str | None = Field(None, max_length=64, description="serial of a DUT mounted otherwise than "
                                           "its mount_euler_deg says")
    sensor_misoriented_about: Literal["x", "y", "z"] = Field("z", description="the DUT's axis it is turned about")
    sensor_misoriented_deg: Real = Field(180.0, ge=-360, le=360, description="how far it is turned")
    sensor_dead_axis: str | None = Field(None, max_length=64, description="serial of a DUT with a dead axis (it "
                                         "reads its bias whatever the pose)")
    sensor_dead_axis_name: Literal["x", "y", "z"] = Field("x", description="which of its axes is dead")
    sensor_out_of_spec: str | None = Field(None, max_length=64, description="serial of a DUT whose part is beyond its "
                                           "data sheet (a bias or a scale a healthy part does not have)")
    sensor_out_of_spec_channel: str = Field("accel", max_length=32, description="that DUT's channel which is")
    sensor_out_of_spec_bias: Real = Field(0.0, ge=-1e6, le=1e6, description="added to each axis's bias, in the "
                                          "channel's unit (g, °/s, gauss)")
    sensor_out_of_spec_scale_pct: Real = Field(0.0, ge=-50, le=50, description="added to each axis's scale factor, %")
    sensor_temperature_tear_rate: Real = Field(
        0.0, ge=0, le=1, description="share of every DUT's TEMP2/TEMP1 reads that straddle an update of the high "
                                     "nibble (not double-buffered on a real ADXL355): off by 256 LSB, about 28 °C")


#: nT per gauss.
NT_PER_GAUSS = 1e5


class SiteField(StrictModel):
    """The Earth's magnetic field at the rig: what a magnetometer's reference is at each pose (its size, and with
    the table's heading_deg its direction). From a survey, or a geomagnetic model for the site and date (WMM,
    IGRF: e.g. `pip install pygeomag`, docs/instruments.md "ST LIS3MDL"); the steel of a chamber and a table
    changes it: measure it where the fixture is."""

    total_intensity_nt: Real = Field(ge=1000, le=100_000, description="its total intensity F, nT")
    inclination_deg: Real = Field(ge=-90, le=90, description="its inclination I, degrees below the horizontal")
    declination_deg: Real = Field(0.0, ge=-180, le=180, description="its declination D, degrees east of true north")
    total_intensity_uncertainty_nt: Real = Field(0.0, ge=0, le=10_000, description="F's standard uncertainty, nT")

    def world_gauss(self, heading_deg: float) -> np.ndarray:
        """The field in the lab's world frame (z up, x the table's x axis at zero angles, at azimuth
        `heading_deg` east of true north), gauss."""
        size = self.total_intensity_nt / NT_PER_GAUSS
        inclination, azimuth = np.radians(self.inclination_deg), np.radians(self.declination_deg - heading_deg)
        return size * np.array([np.cos(inclination) * np.cos(azimuth), -np.cos(inclination) * np.sin(azimuth),
                                -np.sin(inclination)])


class SimulationConfig(StrictModel):
    """Physics of the virtual lab used by `--dry-run` (docs/procedures.md, "The simulated rig")."""

    ambient_c: TemperatureC = 23.0
    chamber_time_constant_min: Real = Field(3.0, ge=0.01, le=1440)
    chamber_noise_c: Real = Field(0.05, ge=0, le=10)
    fixture_time_constant_min: Real = Field(10.0, ge=0.01, le=1440)
    free_cooling_time_constant_min: Real = Field(45.0, ge=0.01, le=10080, description="chamber switched off: its "
                                                 "air relaxes to ambient with this time constant")
    self_heating_c: Real = Field(0.2, ge=0, le=20)
    noise_density_ug_per_rthz: Real | None = Field(None, ge=0, le=100_000, description="every DUT's noise "
                                                   "density; unset: each part's own (its data sheet's)")
    turntable_settle_s: Real = Field(0.5, ge=0, le=600)
    latitude_deg: Real = Field(48.0, ge=-90, le=90, description="the simulated site's latitude where the rig "
                               "config states none (the Earth turns in every lab)")
    heading_deg: Real = Field(30.0, ge=-360, le=360, description="the simulated table's heading where the rig "
                              "config states none")
    magnetic_field: SiteField = Field(SiteField(total_intensity_nt=48_800.0, inclination_deg=64.4, declination_deg=4.4),
                                      description="the simulated site's magnetic field where the rig config states "
                                                  "none (about Munich's in 2026, WMM2025)")
    gyro_bias_instability_dph: Real = Field(0.0, ge=0, le=10_000, description="every simulated gyroscope's bias "
                                            "instability (a flicker floor of its Allan deviation over 1…1000 s), °/h")
    controller_limits_c: tuple[TemperatureC, TemperatureC] = Field(
        (-70.0, 180.0), description="the simulated controller's own set point limits (low, high), where its "
                                    "register map has them; it clamps set points to them as a real one does")
    room_dew_point_c: TemperatureC = Field(12.0, description="the room's air, which a chamber without purge "
                                           "takes in (23 °C at 50 % RH has a dew point near 12 °C)")
    purge_dew_point_c: TemperatureC = Field(-40.0, description="the dry-air purge's dew point (instrument air)")
    moisture_time_constant_min: Real = Field(5.0, ge=0.01, le=1440, description="the air's dew point follows "
                                             "its target with this time constant")
    chamber_overshoot_pct: Real = Field(0.0, ge=0, le=50, description="the air overshoots a set point by this "
                                        "share of the step, peaking three chamber time constants after the ramp arrives")
    cooling_floor_c: TemperatureC | None = Field(None, description="cooling slows towards this temperature (the "
                                                 "compressor's floor): at T, the ramp rate × (T − floor)/(ambient − floor)")
    slot_gradient_c: Real = Field(0.0, ge=0, le=20, description="at 60 °C from ambient, the last slot's air is "
                                  "this much nearer ambient than the first's (the slot at the air inlet leads)")
    slot_lead_pct: Real = Field(0.0, ge=0, le=90, description="the first slot's time constant is this much "
                                "shorter than the last's, linearly between")
    time_constant_per_dut_min: Real = Field(0.0, ge=0, le=60, description="each DUT (its board and socket) adds "
                                            "this to fixture_time_constant_min: a fuller fixture lags more")
    faults: FaultInjection = FaultInjection()

    def fixture_time_constants_s(self, serials: list[str]) -> list[float]:
        """Each DUT's time constant behind its slot's air: the fixture's, grown by its load of DUTs, ±10 % per
        DUT, and shorter towards the inlet by `slot_lead_pct`."""
        nominal_s = 60.0 * (self.fixture_time_constant_min + self.time_constant_per_dut_min * len(serials))
        positions = _slot_positions(len(serials))
        return [dut_time_constant_s(serial, nominal_s) * (1.0 - self.slot_lead_pct / 100.0 * (1.0 - position))
                for serial, position in zip(serials, positions)]

    def slot_offsets_per_c(self, n_duts: int) -> list[float]:
        """Each slot's air offset per °C of air above ambient (negative: nearer ambient)."""
        return [-self.slot_gradient_c / 60.0 * position for position in _slot_positions(n_duts)]


def _slot_positions(n_duts: int) -> list[float]:
    """Each slot's place along the air's path, 0 at the inlet to 1 at the far end."""
    return [k / (n_duts - 1) if n_duts > 1 else 0.0 for k in range(n_duts)]


class RetryPolicy(StrictModel):
    """Transient communication failures (no reply, garbled reply, a port gone) are retried this way."""

    attempts: Whole = Field(5, ge=1, le=20, description="tries in all, the first included")
    first_backoff_s: Real = Field(0.5, ge=0, le=600, description="wait before the second try; doubles each time")
    max_backoff_s: Real = Field(8.0, ge=0, le=3600, description="longest wait between tries")


NotifyEvent = Literal["start", "soak", "fault", "safe", "finish", "early_check"]


class NotifyConfig(StrictModel):
    """Who hears about an unattended run: a webhook (JSON POST) and/or a local command (JSON on stdin)."""

    webhook_url: str | None = Field(None, max_length=2048, pattern=r"^https?://",
                                    description="http(s) URL to POST each event to")
    command: list[Annotated[str, Field(max_length=4096)]] = Field([], max_length=64,
                                                                  description="program and arguments to run for each event")
    events: list[NotifyEvent] = Field(["start", "soak", "fault", "safe", "finish", "early_check"],
                                      description="which events to send")
    timeout_s: Real = Field(10.0, gt=0, le=120, description="longest one delivery may take")


class RigThermal(StrictModel):
    """The rig's own thermal behaviour as measured on it (`rig characterise CAMPAIGN --write RIG` fits and
    writes it): what `rig plan`'s duration estimate plays a plan against. A constant left out falls back to
    its default (THERMAL_DEFAULTS), and `rig plan` says which. Not the simulated lab's physics (`simulation:`)."""

    heating_rate_c_per_min: Real | None = Field(None, ge=0.01, le=50, description="how fast the chamber moves its "
                                                "air up (at most chamber.ramp_rate_c_per_min, the commanded rate)")
    cooling_rate_c_per_min: Real | None = Field(None, ge=0.01, le=50, description="how fast it moves it down at "
                                                "room temperature")
    cooling_floor_c: TemperatureC | None = Field(None, description="cooling slows towards this temperature: at T, "
                                                 "the cooling rate × (T − floor)/(room − floor); unset: it does not")
    room_c: TemperatureC | None = Field(None, description="the room the chamber stands in (the floor is reckoned "
                                        "from it)")
    chamber_time_constant_min: Real | None = Field(None, ge=0.01, le=1440, description="the air's lag behind the "
                                                   "controller's ramp")
    chamber_overshoot_pct: Real | None = Field(None, ge=0, le=50, description="the controller drives past a set "
                                               "point by this share of the step, peaking three air time constants "
                                               "after its ramp arrives")
    fixture_time_constant_min: Real | None = Field(None, ge=0.01, le=1440, description="the slowest DUT's lag "
                                                   "behind the air (a soak waits for the slowest)")
    measured: str | None = Field(None, max_length=500, description="where and when these were measured")


#: What the estimate uses for a thermal constant the rig config leaves out (the heating and cooling rates:
#: the chamber's commanded ramp rate; no floor; no overshoot).
THERMAL_DEFAULTS: dict[str, float | None] = {"cooling_floor_c": None, "room_c": 23.0, "chamber_time_constant_min": 3.0,
                                             "chamber_overshoot_pct": 0.0, "fixture_time_constant_min": 10.0}


@dataclass(frozen=True)
class EstimateThermal:
    """The thermal constants an estimate plays a plan with, and the names of those that are defaults."""

    heating_rate_c_per_min: float
    cooling_rate_c_per_min: float
    cooling_floor_c: float | None
    room_c: float
    chamber_time_constant_min: float
    chamber_overshoot_pct: float
    fixture_time_constant_min: float
    defaults: tuple[str, ...]


class RigConfig(StrictModel):
    name: str = Field(min_length=1, max_length=128)
    description: str = Field("", max_length=10_000)
    chamber: ChamberConfig
    turntable: TurntableConfig
    fixture: FixtureConfig
    retry: RetryPolicy = RetryPolicy()
    notify: NotifyConfig = NotifyConfig()
    simulation: SimulationConfig = SimulationConfig()
    thermal: RigThermal = Field(RigThermal(), description="the rig's own thermal constants, measured (rig "
                                "characterise): what duration estimates use")
    gravity_m_s2: Real = Field(STANDARD_GRAVITY_M_S2, ge=9.7, le=9.9,
                               description="the site's gravity (a survey or a gravity model); the standard value "
                                           "by default, said so in reports")
    gravity_uncertainty_m_s2: Real = Field(0.0, ge=0.0, le=0.05, description="its standard uncertainty")
    registry: str | None = Field(None, max_length=4096, description="where finished calibrations are recorded: an "
                                 "SQLite file (relative to this file) or a postgresql:// URL")
    latitude_deg: Real | None = Field(None, ge=-90, le=90, description="the site's latitude: the Earth's rate "
                                      "(15.04 °/h) is part of every gyroscope reference, its vertical component "
                                      "sin(latitude) × 15.04 °/h; unset: left in the gyroscope's bias, said so")
    heading_deg: Real | None = Field(None, ge=-360, le=360, description="the azimuth of the table's x axis (world "
                                     "x at zero angles), degrees east of true north: with latitude_deg, the Earth's "
                                     "horizontal rate (cos(latitude) × 15.04 °/h) is part of the reference too")
    magnetic_field: SiteField | None = Field(None, description="the site's magnetic field where the fixture is: a "
                                             "magnetometer's reference (its direction needs heading_deg too)")
    lab: LabConfig | None = Field(None, description="the laboratory and the place of calibration its certificates "
                                  "state; unset: they say it is not stated")
    references: References = Field(References(), description="each reference's certificate, issuer and due date "
                                   "(the certificates' traceability)")
    references_overdue: Literal["warn", "refuse"] = Field("warn", description="a reference past its due date: rig "
                                                          "plan and rig run warn, or refuse to run")

    @model_validator(mode="after")
    def _surveyed_gravity_stated(self) -> RigConfig:
        """A gravity survey named as a reference with the standard value left in its place would trace the
        certificates to a survey whose result they do not use."""
        if self.references.site_gravity is not None and "gravity_m_s2" not in self.model_fields_set:
            raise ValueError("references.site_gravity names a gravity survey but gravity_m_s2 is not stated: "
                             "state the surveyed value (and gravity_uncertainty_m_s2)")
        return self

    @model_validator(mode="after")
    def _cooling_floor_below_the_chamber(self) -> RigConfig:
        floor = self.simulation.cooling_floor_c
        if floor is not None and floor >= min(self.chamber.min_setpoint_c, self.simulation.ambient_c):
            raise ValueError(f"simulation.cooling_floor_c: {floor:g} °C is not below the chamber's lowest set point "
                             f"({self.chamber.min_setpoint_c:g} °C) and the ambient: a compressor cools towards it")
        return self

    @model_validator(mode="after")
    def _thermal_floor_below_the_chamber(self) -> RigConfig:
        floor = self.thermal.cooling_floor_c
        if floor is not None and floor >= self.chamber.min_setpoint_c:
            raise ValueError(f"thermal.cooling_floor_c: {floor:g} °C is not below the chamber's lowest set point "
                             f"({self.chamber.min_setpoint_c:g} °C): cooling slows towards it")
        return self

    def estimate_thermal(self) -> EstimateThermal:
        """The constants the duration estimate uses: the measured ones (`thermal:`), a default for any left out;
        a rate above the commanded ramp rate is the commanded rate (the controller ramps no faster)."""
        measured = self.thermal
        commanded = self.chamber.ramp_rate_c_per_min
        values: dict[str, float | None] = {}
        defaults = []
        for name in ("heating_rate_c_per_min", "cooling_rate_c_per_min", *THERMAL_DEFAULTS):
            value = getattr(measured, name)
            if value is None and not (name == "cooling_floor_c" and measured.cooling_rate_c_per_min is not None):
                defaults.append(name)
                value = THERMAL_DEFAULTS.get(name, commanded)
            values[name] = value
        heating, cooling = values["heating_rate_c_per_min"], values["cooling_rate_c_per_min"]
        assert heating is not None and cooling is not None
        room, chamber_tau, overshoot, fixture_tau = (values["room_c"], values["chamber_time_constant_min"],
                                                     values["chamber_overshoot_pct"], values["fixture_time_constant_min"])
        assert room is not None and chamber_tau is not None and overshoot is not None and fixture_tau is not None
        return EstimateThermal(min(heating, commanded), min(cooling, commanded), values["cooling_floor_c"], room,
                               chamber_tau, overshoot, fixture_tau, tuple(defaults))

    @property
    def gravity_g(self) -> float:
        """The site's gravity in standard g: the magnitude every reference and every |g| figure uses."""
        return site_gravity_g(self.gravity_m_s2)
