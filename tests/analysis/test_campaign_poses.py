"""Analyses at one setpoint take its calibration poses, not the verification poses of another schedule."""

from pathlib import Path

from accelcal_rig.analysis.campaign_poses import poses_at_setpoint


def test_verification_poses_are_left_out(paper_campaign: Path) -> None:
    setpoint, duts, numbers = poses_at_setpoint(paper_campaign, 20.0)
    assert setpoint == 20.0 and list(numbers) == list(range(1, 25))  # the 24 Table 1 poses, not v1…v12
    for poses in duts.values():
        assert len(poses.mean) == 24 and not poses.verification.any()
        assert poses.reference.shape == (24, 3) and poses.channel == "accel"
