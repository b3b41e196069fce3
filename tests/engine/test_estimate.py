"""The duration estimate against what a dry run of the same campaign actually took on its clock."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.engine.preparation import prepare
from tests.conftest import REPO, TINY_PROCEDURE


def test_estimate_of_the_paper_campaign_is_within_3_percent_of_its_dry_run(paper_campaign: Path) -> None:
    prepared = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml")
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    with h5py.File(paper_campaign, "r") as file:
        took_s = float(file["poses/t_end_s"][:].max())
        reached = {float(g.attrs["setpoint_c"]): float(g.attrs["t_reached_s"]) for g in file["soaks"].values()}
        stable = {float(g.attrs["setpoint_c"]): float(g.attrs["t_stable_s"]) for g in file["soaks"].values()}
    assert estimate.total_s == pytest.approx(took_s, rel=0.03)
    first = estimate.setpoints[0]
    assert first.ramp_s == pytest.approx(reached[-40.0], abs=prepared.procedure.model.soak.poll_s)
    soaks = np.array([stable[s] - reached[s] for s in prepared.plan.setpoints_c])
    estimated = np.array([row.soak_s for row in estimate.setpoints])
    assert np.all(np.abs(estimated - soaks) < 0.25 * soaks)  # one setpoint's soak depends on the noise drawn
    assert all(row.soak_outcome == "stable" for row in estimate.setpoints)


def test_remaining_time_counts_down_to_zero() -> None:
    prepared = prepare(REPO / "procedures" / "quick-6pos.yaml")
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    first, second = estimate.setpoints
    assert estimate.remaining_s([6, 6], 0) == pytest.approx(estimate.total_s)
    assert estimate.remaining_s([6, 6], 0, phase_elapsed_s=60.0) == pytest.approx(estimate.total_s - 60.0)
    assert estimate.remaining_s([3, 6], 0, in_pose_phase=True) == pytest.approx(3 * first.pose_s + second.total_s)
    assert estimate.remaining_s([3, 0], 0, in_pose_phase=True) == pytest.approx(3 * first.pose_s)  # resumed
    assert estimate.remaining_s([0, 0], 1, in_pose_phase=True) == 0.0


def test_a_soak_that_cannot_be_met_shows_as_timeout(write) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("band_c: 0.3", "band_c: 0.01"))
    prepared = prepare(path)
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, prepared.plan)
    assert estimate.setpoints[0].soak_outcome == "timeout"
    assert estimate.setpoints[0].soak_s == pytest.approx(120 * 60.0)
