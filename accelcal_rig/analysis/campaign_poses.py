"""The poses of one setpoint of a campaign file, for analyses that work at one temperature."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from accelcal_rig.store.read import DutPoses, read_dut_poses, rows_at_setpoint, usable_campaign


def poses_at_setpoint(path: Path, setpoint_c: float | None) -> tuple[float, dict[str, DutPoses], np.ndarray]:
    """(setpoint, each DUT's poses there, their pose numbers); `setpoint_c` None: the file's only one."""
    campaign = usable_campaign(path)
    setpoint_c, rows = rows_at_setpoint(path, campaign, setpoint_c)
    numbers = campaign.pose_column("pose_number")[rows]
    duts = {serial: _select(read_dut_poses(campaign, serial), rows) for serial in campaign.serials}
    return setpoint_c, duts, numbers


def _select(poses: DutPoses, rows: np.ndarray) -> DutPoses:
    return replace(poses, setpoint_c=poses.setpoint_c[rows], t_s=poses.t_s[rows], temperature_c=poses.temperature_c[rows],
                   mean_g=poses.mean_g[rows], stderr_g=poses.stderr_g[rows], reference_g=poses.reference_g[rows],
                   truth_parameters=None if poses.truth_parameters is None else poses.truth_parameters[rows])
