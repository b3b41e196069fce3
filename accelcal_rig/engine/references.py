"""What each channel should read at a pose, by the quantity it measures: the references a pose stores beside the
means (`REFERENCES`), and what of the rig config each needs (`REFERENCE_NEEDS`). The one place before the
journal that knows the quantities: an accelerometer's is the site's gravity, a gyroscope's the table's and the
Earth's rate, a magnetometer's the site's magnetic field, each in the DUT's frame through the pose, the table's
kinematics and the nominal mount. A quantity with no reference here is refused before anything moves
(engine/preparation.py)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from accelcal_rig.core.earth import earth_rate_world_dps
from accelcal_rig.parts.part import Channel
from accelcal_rig.plan.steps import Measurement, RateStep

if TYPE_CHECKING:
    from accelcal_rig.engine.run_context import RunContext


@dataclass(frozen=True)
class PoseInstant:
    """Where the table was while a record's samples were taken: the step (its pose, its rate), the angles
    read as the samples began, and how long they took."""

    step: Measurement
    measured_angles_deg: np.ndarray
    duration_s: float


def _gravity_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The site's gravity (in standard g) in the DUT's frame: the commanded pose, the nominal mount. A rate
    step's turn about the vertical changes it not; the centripetal acceleration of a DUT off the rate axis is
    not in it (its radius is not known): no accelerometer fit uses a rate step."""
    return run.rig.gravity_g * (run.fixture_to_dut[serial] @ np.array(at.step.pose.gravity_fixture))


def _rate_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The true angular rate in the DUT's frame, °/s: the table's (zero through a pose, the commanded rate
    about the fixture axis through a rate step) and the Earth's as far as the rig config places it."""
    table = np.array(at.step.rate_fixture_dps)
    return run.fixture_to_dut[serial] @ (table + _earth_rate_fixture_dps(run, at))


#: Points over a record's samples at which a turning table's Earth rate is averaged.
_EARTH_POINTS = 64


def _earth_rate_fixture_dps(run: RunContext, at: PoseInstant) -> np.ndarray:
    """The Earth's rate in the fixture frame over the record's samples: nothing where the rig config states no
    latitude; its vertical component always, along "up" whatever turns about the vertical; its horizontal one
    (with a heading) turns with a rate step's axis, averaged over the samples from the angles read as they
    began."""
    if run.rig.latitude_deg is None:
        return np.zeros(3)
    world = earth_rate_world_dps(run.rig.latitude_deg, run.rig.heading_deg)
    angles = np.broadcast_to(np.asarray(at.measured_angles_deg, dtype=float),
                             (_EARTH_POINTS, len(at.measured_angles_deg))).copy()
    if isinstance(at.step, RateStep):
        times = (np.arange(_EARTH_POINTS) + 0.5) / _EARTH_POINTS * at.duration_s
        angles[:, at.step.rate_axis] += at.step.rate_dps * times
    return run.kinematics.world_in_fixture(angles, world).mean(axis=0)


def _field_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The site's magnetic field in the DUT's frame, gauss: the rig config's field at the commanded pose through
    the table's heading and the nominal mount. Without the heading its direction about the vertical is not known
    (taken as 0: only the field's size is then a reference, and the magnetometer's model fits against that)."""
    field = run.rig.magnetic_field
    assert field is not None, "preparation refuses a magnetometer on a rig that states no magnetic_field"
    world = field.world_gauss(run.rig.heading_deg if run.rig.heading_deg is not None else 0.0)
    return run.fixture_to_dut[serial] @ run.kinematics.world_in_fixture(np.array(at.step.pose.angles_deg), world)


#: What a channel should read at a pose, by the quantity it measures.
REFERENCES: dict[str, Callable[[RunContext, str, Channel, PoseInstant], np.ndarray]] = {
    "acceleration": _gravity_reference, "angular rate": _rate_reference, "magnetic field": _field_reference}
#: What of the rig config a quantity's reference needs (a key that must be stated), and what it is.
REFERENCE_NEEDS: dict[str, tuple[str, str]] = {"magnetic field": ("magnetic_field", "the site's magnetic field")}
#: Quantities a DUT off the rate axis may read beyond its range on a turning table (its centripetal
#: acceleration, 1.5 g at 5 cm and 1000 °/s): a saturated block there is expected, and nothing uses it.
SATURATES_TURNING = frozenset({"acceleration"})
