"""The run's header says what a plan measures: each kind of pose and how many setpoints hold it, not every
setpoint times the calibration schedule (the paper campaign's verification-only setpoints hold none of it)."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.composition import plan_composition
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO


def test_the_paper_campaign_is_its_calibration_and_its_verification_poses() -> None:
    prepared = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml")
    plan, procedure = prepared.plan, prepared.procedure.model
    calibration = len(procedure.setpoints_c) * len(plan.poses)
    verified_at = {s.setpoint_c for s in plan.pose_steps if s.stored_kind == "verify"}
    verification = len(verified_at) * len(plan.verification_poses)
    assert calibration + verification == len(plan.pose_steps)
    assert len(plan.setpoints_c) * len(plan.poses) != len(plan.pose_steps)  # what the header used to multiply
    assert plan_composition(plan) == (
        f"{len(plan.pose_steps)} poses: {calibration} calibration ({len(plan.poses)} × {len(procedure.setpoints_c)} "
        f"setpoints) + {verification} verification ({len(plan.verification_poses)} × {len(verified_at)} setpoints)")


def test_a_cool_down_is_its_records_at_one_setpoint() -> None:
    plan = prepare(REPO / "procedures" / "cooldown-60c.yaml").plan
    assert plan_composition(plan) == (f"{len(plan.pose_steps)} poses: {len(plan.pose_steps)} cool-down records "
                                      f"({len(plan.pose_steps)} × 1 setpoint)")


def test_the_run_header_states_it(paper_campaign: Path) -> None:
    prepared = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml")
    header = next(e.message for e in load_campaign(paper_campaign).events if e.kind == "plan")
    assert header.startswith(f"{len(prepared.plan.setpoints_c)} setpoints; {plan_composition(prepared.plan)}; 4 DUTs")
