"""The poses of one setpoint of a campaign file, for analyses that work at one temperature."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.store.read import VectorPoses, read_vector_poses, rows_at_setpoint, usable_campaign
from accelcal_rig.store.records import STATIC_KINDS

#: The quantity these analyses are of: a tilt check's and a cool-down's accelerometers.
ACCELERATION = "acceleration"


def poses_at_setpoint(path: Path, setpoint_c: float | None) -> tuple[float, dict[str, VectorPoses], np.ndarray]:
    """(setpoint, each DUT's accelerometer poses there, their pose numbers); `setpoint_c` None: the file's only
    one. A DUT without an accelerometer is not among them."""
    campaign = usable_campaign(path)
    setpoint_c, rows = rows_at_setpoint(path, campaign, setpoint_c)
    # The accelerometer's poses at rest (read_vector_poses keeps those alone, a gyroscope's rate steps and noise
    # blocks aside), of the calibration schedule: verification poses are another, with their own numbering.
    keys = campaign.pose_column("step_key")
    static = np.isin(keys, list(campaign.header.plan.keys_of(*STATIC_KINDS)))
    calibration = static & ~np.isin(keys, list(campaign.header.plan.verification_keys))
    numbers = campaign.pose_column("pose_number")[rows & calibration]
    chosen = (rows & calibration)[static]
    accelerometers = {serial: campaign.channel_of(serial, ACCELERATION) for serial in campaign.serials}
    duts = {serial: read_vector_poses(campaign, serial, info.name).subset(chosen)
            for serial, info in accelerometers.items() if info is not None}
    return setpoint_c, duts, numbers
