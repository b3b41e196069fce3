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
    read before the samples, how long they took, and how long after the read the first was taken (on a
    turning table the read angle is the turn's phase only then)."""

    step: Measurement
    measured_angles_deg: np.ndarray
    duration_s: float
    lead_s: float = 0.0


def _gravity_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The site's gravity (in standard g) in the DUT's frame: the commanded pose, the nominal mount; through a
    rate step, averaged over the samples as the turn carries it (a turn about the vertical changes it not, one
    about any other axis turns it in the fixture frame). The centripetal acceleration of a DUT off the rate
    axis is not in it (its radius is not known): no accelerometer fit uses a rate step."""
    up = np.array(at.step.pose.gravity_fixture)
    if isinstance(at.step, RateStep):
        up = run.kinematics.gravity_in_fixture(_turning_angles(at, np.array(at.step.pose.angles_deg))).mean(axis=0)
    return run.rig.gravity_g * (run.fixture_to_dut[serial] @ up)


def _rate_reference(run: RunContext, serial: str, channel: Channel, at: PoseInstant) -> np.ndarray:
    """The true angular rate in the DUT's frame, °/s: the table's (zero through a pose, the commanded rate
    about the fixture axis through a rate step, whichever table axis turns it) and the Earth's as far as the
    rig config places it."""
    table = np.array(at.step.rate_fixture_dps)
    return run.fixture_to_dut[serial] @ (table + _earth_rate_fixture_dps(run, at))


#: Points over a record's samples at which what a turning table carries is averaged: at least this many, and
#: one every _DEGREES_PER_POINT of the turn.
_EARTH_POINTS = 64
_DEGREES_PER_POINT = 5.0


def _turning_angles(at: PoseInstant, angles_deg: np.ndarray) -> np.ndarray:
    """(points, axes): `angles_deg` at the midpoints of a record's samples, a rate step's axis advanced at its
    rate from the angle read before them (the same angles at every point for a record at rest)."""
    points = _EARTH_POINTS
    if isinstance(at.step, RateStep):
        points = max(points, int(np.ceil(abs(at.step.table_rate_dps) * at.duration_s / _DEGREES_PER_POINT)))
    angles = np.broadcast_to(np.asarray(angles_deg, dtype=float), (points, len(angles_deg))).copy()
    if isinstance(at.step, RateStep):
        times = at.lead_s + (np.arange(points) + 0.5) / points * at.duration_s
        angles[:, at.step.rate_axis] = at.measured_angles_deg[at.step.rate_axis] + at.step.table_rate_dps * times
    return angles


def _earth_rate_fixture_dps(run: RunContext, at: PoseInstant) -> np.ndarray:
    """The Earth's rate in the fixture frame over the record's samples: nothing where the rig config states no
    latitude; else through the angles read as they began, a rate step's axis advanced at its rate, averaged
    over the samples (what turns about the Earth's rate keeps its component along the turn)."""
    if run.rig.latitude_deg is None:
        return np.zeros(3)
    world = earth_rate_world_dps(run.rig.latitude_deg, run.rig.heading_deg)
    return run.kinematics.world_in_fixture(_turning_angles(at, at.measured_angles_deg), world).mean(axis=0)


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
