"""The accelerometer's channel model: Eq. 1 against gravity, the paper's method (fit/vector_model.py).

Its reference at a pose is the site's gravity in standard g (the rig config's `gravity_m_s2`, with its
uncertainty) turned into the DUT's frame by the commanded pose and the mount; its angle figure is Eq. 10's
tilt; a dry run stores its truth with every pose (the true parameters and the true specific force).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2, gravity_statement
from accelcal_rig.fit.channel_model import FlightStackOffsets, NoiseFigures
from accelcal_rig.fit.options import FitOptions
from accelcal_rig.fit.vector_model import Eq1Model, VectorQuantity
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import VectorPoses, site_gravity

#: The paper whose method the accelerometer's calibration follows.
METHOD = "Eq. 1, U_SF = M·C·S·(U − b)"


def _stored_truth(campaign: Campaign, serial: str, channel: str,
                  poses: VectorPoses) -> tuple[np.ndarray | None, np.ndarray | None]:
    """A dry run keeps the accelerometer's true parameters and true specific force with each pose."""
    parameters, force = campaign.truth_column(serial, "parameters"), campaign.truth_column(serial, "gravity_g")
    if parameters is None:
        return None, None
    return parameters[poses.rows], None if force is None else force[poses.rows]


def _gravity(figures: Mapping[str, Any]) -> list[tuple[str, str]]:
    return [("gravity", gravity_statement(float(figures.get("gravity_m_s2", STANDARD_GRAVITY_M_S2))))]


ACCELERATION = VectorQuantity(
    quantity="acceleration", sensor="accelerometer", unit="g", milli="mg", magnitude_label="|g|",
    reference_label="gravity", magnitude_figure=("gravity_m_s2", STANDARD_GRAVITY_M_S2), angle="tilt",
    site=site_gravity, truth=_stored_truth, method=METHOD, micro="µg", magnitude_source="site's gravity",
    size_source="gravity", angle_label="largest tilt error (Eq. 10)",
    result_digits={"bias": "+.3f", "non-orthogonality": "+.4f", "misalignment": "+.4f"},
    noise=NoiseFigures("vrw_m_s_per_rthr", "velocity random walk", "m/s/√h", STANDARD_GRAVITY_M_S2 * 60.0,
                       "bias_instability_ug", "µg", 1e6, ".5f", ".1f"),
    statements=_gravity, setpoint_check=True,
    flight_stack=FlightStackOffsets("accelerometer", ("bias_x_g", "bias_y_g", "bias_z_g"), STANDARD_GRAVITY_M_S2,
                                    "m/s²"),
)

MODEL = Eq1Model(ACCELERATION)


def accelerometer_poses(campaign: Campaign, serial: str, options: FitOptions | None = None) -> VectorPoses:
    """The DUT's accelerometer poses as its model reads them (the site's gravity, the truth of a dry run; each
    pose's approach with `fit.hysteresis`); ValueError for a DUT without an accelerometer."""
    info = campaign.channel_of(serial, ACCELERATION.quantity)
    if info is None:
        raise ValueError(f"sensor {serial} has no accelerometer")
    return MODEL.records(campaign, info, serial, options or FitOptions()).poses
