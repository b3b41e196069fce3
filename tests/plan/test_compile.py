import numpy as np

from accelcal_rig.engine.session import prepare
from accelcal_rig.plan.kinematics import TurntableKinematics
from tests.conftest import REPO


def test_paper_plan_has_a_soak_then_24_poses_at_each_of_11_setpoints() -> None:
    prepared = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml")
    plan = prepared.plan
    assert len(plan.steps) == 11 * 25
    assert len(plan.pose_steps) == 264
    assert plan.steps[0].key == "T-40/soak"
    assert plan.steps[1].key == "T-40/pose01"
    assert plan.steps[-1].key == "T60/pose24"
    assert len({s.key for s in plan.steps}) == len(plan.steps)  # keys are unique


def test_plan_angles_reproduce_the_schedule_directions() -> None:
    prepared = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml")
    kinematics = TurntableKinematics(prepared.rig.model.turntable.axes)
    angles = np.array([p.angles_deg for p in prepared.plan.poses])
    gravity = np.array([p.gravity_fixture for p in prepared.plan.poses])
    np.testing.assert_allclose(kinematics.gravity_in_fixture(angles), gravity, atol=1e-8)


def test_compiling_twice_gives_the_same_fingerprint_and_a_change_changes_it(write) -> None:
    from tests.conftest import TINY_PROCEDURE

    first = prepare(write("tiny.yaml", TINY_PROCEDURE)).plan
    again = prepare(write("tiny.yaml", TINY_PROCEDURE)).plan
    assert first.fingerprint == again.fingerprint
    other = prepare(write("tiny.yaml", TINY_PROCEDURE.replace("[30]", "[31]"))).plan
    assert other.fingerprint != first.fingerprint


def test_explicit_schedule_keeps_the_given_angles(write) -> None:
    from tests.conftest import TINY_PROCEDURE

    text = TINY_PROCEDURE.replace("schedule: {kind: six-position}",
                                  "schedule: {kind: explicit, angles_deg: [[0, 0, 0], [0, 90, 0], [10, 180, 370], "
                                  "[0, 90, 90], [0, -90, 90], [0, -90, 0]]}")
    plan = prepare(write("tiny.yaml", text)).plan
    assert [p.angles_deg for p in plan.poses][:3] == [(0, 0, 0), (0, 90, 0), (10, -180, 10)]
    np.testing.assert_allclose(plan.poses[1].gravity_fixture, [0, 1, 0], atol=1e-12)
