"""Which ± full scale each channel takes at a step: `acquisition.ranges`, or a channel's finer range
(`acquisition.fine_ranges`) where the step's readings stay well inside it. A gyroscope's code at ±2000 °/s
(0.061 °/s) is coarser than its noise, so its means at rest and at low rates carry quantisation no averaging
takes out; at ±250 °/s the code (0.0076 °/s) is finer than the noise. The procedure's check
(config/load.py) admits finer ranges for gyroscopes alone, so a step's rate bounds what they read."""

from __future__ import annotations

from functools import partial

import numpy as np

from accelcal_rig.config.procedure import Acquisition
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.instruments.interfaces import Sensor
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.plan.steps import Measurement

#: A finer range takes a step whose table rate is at most this share of it: the rest is room for the bias,
#: the noise, the Earth's rate and the table's rate error.
FINE_RANGE_SHARE = 0.8


def step_ranges(acquisition: Acquisition, step: Measurement) -> dict[str, float]:
    """Each channel's range at `step`."""
    ranges = dict(acquisition.ranges)
    rate_dps = float(np.linalg.norm(step.rate_fixture_dps))
    for name, fine in acquisition.fine_ranges.items():
        if rate_dps <= FINE_RANGE_SHARE * fine:
            ranges[name] = fine
    return ranges


def set_ranges(run: RunContext, ranges: dict[str, float]) -> None:
    """Every DUT at `ranges` before the step's block, unless it is there already: in standby, configured and read
    back (the driver's), measuring again after its start-up; said in the event log."""
    if ranges == run.sensor_ranges:
        return
    odr_hz = run.procedure.acquisition.odr_hz
    for sensor in run.sensors:
        run.retrier.call(partial(_reconfigure, sensor, ranges, odr_hz_of(sensor.part, odr_hz)))
    run.events.debug("ranges", ", ".join(f"{name} ±{value:g}" for name, value in ranges.items()))
    run.sensor_ranges = dict(ranges)


def _reconfigure(sensor: Sensor, ranges: dict[str, float], odr_hz: float) -> None:
    sensor.standby()
    sensor.configure(ranges, odr_hz)
    sensor.start_measurement()
