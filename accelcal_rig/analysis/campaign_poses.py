"""The poses of one setpoint of a campaign file, for analyses that work at one temperature."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.store.read import DutPoses, read_dut_poses, rows_at_setpoint, usable_campaign
from accelcal_rig.store.records import STATIC_KINDS


def poses_at_setpoint(path: Path, setpoint_c: float | None) -> tuple[float, dict[str, DutPoses], np.ndarray]:
    """(setpoint, each DUT's poses there, their pose numbers); `setpoint_c` None: the file's only one."""
    campaign = usable_campaign(path)
    setpoint_c, rows = rows_at_setpoint(path, campaign, setpoint_c)
    # The accelerometer's poses at rest (read_dut_poses keeps those alone, a gyroscope's rate steps and noise
    # blocks aside), of the calibration schedule: verification poses are another, with their own numbering.
    keys = campaign.pose_column("step_key")
    static = np.isin(keys, list(campaign.header.plan.keys_of(*STATIC_KINDS)))
    calibration = static & ~np.isin(keys, list(campaign.header.plan.verification_keys))
    numbers = campaign.pose_column("pose_number")[rows & calibration]
    chosen = (rows & calibration)[static]
    duts = {serial: read_dut_poses(campaign, serial).subset(chosen) for serial in campaign.serials}
    return setpoint_c, duts, numbers
