"""Every DUT's temperature at one poll, the bridges asked at once: a fixture of 64 DUTs is polled in the
time of a few exchanges, not 64 of them in a row."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from accelcal_rig.instruments.capabilities import TemperaturePosting
from accelcal_rig.instruments.interfaces import Sensor


def read_temperatures_together(sensors: Sequence[Sensor]) -> np.ndarray:
    """Each sensor's temperature (°C). Sensors that can (TemperaturePosting) get their request first and
    are collected after; any whose quick read is not sure is read again on its own, as are sensors without it."""
    posted = [sensor if isinstance(sensor, TemperaturePosting) and sensor.begin_temperature_read() else None
              for sensor in sensors]
    quick = [poster.end_temperature_read() if poster is not None else None for poster in posted]
    return np.array([value if value is not None else sensor.read_temperature_c()
                     for sensor, value in zip(sensors, quick)])
