"""Open every instrument of a rig config with its real driver, at given endpoints."""

from __future__ import annotations

from dataclasses import dataclass, field

from accelcal_rig.config.load import LoadedConfig
from accelcal_rig.config.rig import ChamberConfig, RigConfig, SensorConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import RegisterTransport, SerialBridge, SpidevBus
from accelcal_rig.instruments.chamber_modbus import ModbusChamber
from accelcal_rig.instruments.interfaces import RigInstruments
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.parts.registry import part


@dataclass(frozen=True)
class Endpoints:
    """Where each instrument answers: `chamber` is host:port (Modbus TCP) or a serial device (RTU)."""

    chamber: str
    turntable: str
    sensors: dict[str, str] = field(default_factory=dict)
    chamber_over_tcp: bool = True


def configured_endpoints(rig: LoadedConfig[RigConfig]) -> Endpoints:
    """The endpoints the rig config names; a missing one is an error pointing at its key."""
    model = rig.model
    missing = "no endpoint given: set it, or run with --dry-run to simulate this rig"
    if not model.chamber.endpoint:
        raise rig.error(("chamber", "endpoint"), missing)
    if not model.turntable.endpoint:
        raise rig.error(("turntable", "endpoint"), missing)
    sensors = {}
    for index, sensor in enumerate(model.fixture.sensors):
        if not sensor.endpoint:
            raise rig.error(("fixture", "sensors", index, "endpoint"), missing)
        sensors[sensor.serial] = sensor.endpoint
    return Endpoints(model.chamber.endpoint, model.turntable.endpoint, sensors,
                     chamber_over_tcp=model.chamber.driver == "modbus-tcp")


def connect_rig(rig: RigConfig, endpoints: Endpoints, clock: Clock) -> RigInstruments:
    """Open chamber, turntable and every sensor; if one fails, close those already open and raise."""
    opened: list = []
    try:
        opened.append(_chamber(rig.chamber, endpoints))
        opened.append(SerialTurntable.open(endpoints.turntable, rig.turntable.line_protocol(),
                                           len(rig.turntable.axes), rig.turntable.baudrate,
                                           rig.turntable.timeout_s))
        for sensor in rig.fixture.sensors:
            transport = _transport(sensor, endpoints.sensors[sensor.serial], rig.retry.attempts, clock)
            opened.append(Adxl355(transport, sensor.serial, clock, part(sensor.part)))
    except BaseException:
        for device in opened:
            device.close()
        raise
    return RigInstruments(opened[0], opened[1], opened[2:])


def _chamber(config: ChamberConfig, endpoints: Endpoints) -> ModbusChamber:
    registers = config.register_map()
    if endpoints.chamber_over_tcp:
        host, _, port = endpoints.chamber.rpartition(":")
        if not host or not port.isdigit():
            raise InstrumentError(f"chamber (modbus-tcp {endpoints.chamber}): endpoint is not host:port")
        return ModbusChamber.tcp(host, int(port), registers, config.device_id, config.timeout_s)
    return ModbusChamber.rtu(endpoints.chamber, registers, config.device_id, config.baudrate, config.parity,
                             config.stopbits, config.timeout_s)


def _transport(sensor: SensorConfig, endpoint: str, attempts: int, clock: Clock) -> RegisterTransport:
    if sensor.driver == "spidev":
        bus, _, chip_select = endpoint.partition(".")
        if not (bus.isdigit() and chip_select.isdigit()):
            raise InstrumentError(f"sensor {sensor.serial} (spidev {endpoint}): endpoint is not bus.chip_select")
        return SpidevBus.open(int(bus), int(chip_select), sensor.spi_speed_hz)
    return SerialBridge.open(endpoint, sensor.baudrate, sensor.timeout_s, attempts, clock.sleep)
