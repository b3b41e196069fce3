"""The ways a DUT's registers are reached, as registered sensor drivers: a serial bridge, Linux spidev."""

from __future__ import annotations

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.adxl355_transport import RegisterTransport, SerialBridge, SpidevBus
from accelcal_rig.instruments.definitions import SensorDriver
from accelcal_rig.parts.registry import part

#: The simulated part the DUT's `part:` names (its part's `simulator`), behind a bridge.
_BRIDGE_SIMULATOR = "accelcal_rig.sim.sensor_bridges:serve_part_bridge"
_PROTOCOL = "accelcal_rig.instruments.adxl355_transport"


def _open_bridge(sensor: SensorConfig, endpoint: str, attempts: int, clock: Clock) -> RegisterTransport:
    return SerialBridge.open(endpoint, sensor.baudrate, sensor.timeout_s, attempts, clock.sleep)


def _open_spidev(sensor: SensorConfig, endpoint: str, attempts: int, clock: Clock) -> RegisterTransport:
    bus, _, chip_select = endpoint.partition(".")
    if not (bus.isdigit() and chip_select.isdigit()):
        raise InstrumentError(f"sensor {sensor.serial} (spidev {endpoint}): endpoint is not bus.chip_select")
    return SpidevBus.open(int(bus), int(chip_select), sensor.spi_speed_hz, part(sensor.part).spi)


SERIAL_BRIDGE = SensorDriver("serial-bridge", _open_bridge, simulator=_BRIDGE_SIMULATOR, protocol=_PROTOCOL)
#: A dry run has no SPI bus: the DUT is simulated behind a bridge.
SPIDEV = SensorDriver("spidev", _open_spidev, simulator=_BRIDGE_SIMULATOR, protocol=_PROTOCOL,
                      simulated_by="serial-bridge")
