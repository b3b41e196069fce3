import numpy as np
import pytest

from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.plan.kinematics import TurntableKinematics
from accelcal_rig.plan.steps import (
    AdvanceRamp,
    CheckSetpoint,
    CooldownRecord,
    MeasurePose,
    Ramp,
    RampSegment,
    RateStep,
    Soak,
    StartSoftwareRamp,
    VerifyPose,
)
from tests.conftest import REPO


def test_paper_plan_ramps_soaks_measures_and_verifies_at_each_setpoint_and_between() -> None:
    plan = prepare(REPO / "procedures" / "paper-24pos-thermal.yaml").plan
    calibration, verification = list(range(-40, 61, 10)), [-15, 15, 45]
    assert [s.setpoint_c for s in plan.stages] == sorted(calibration + verification)  # passed on the way up
    for stage in plan.stages:
        assert stage.entry == stage.restart_entry == (Ramp(stage.setpoint_c), Soak(f"T{stage.setpoint_c:g}/soak",
                                                                                    stage.setpoint_c))
        poses = [MeasurePose] * 24 + [CheckSetpoint] if stage.setpoint_c in calibration else []
        assert [type(s) for s in stage.body] == poses + [VerifyPose] * 12
    assert len(plan.pose_steps) == 11 * 36 + 3 * 12
    keys = [s.key for s in plan.records]
    assert keys[:2] == ["T-40/soak", "T-40/pose01"] and keys[25:27] == ["T-40/verify01", "T-40/verify02"]
    assert keys[-1] == "T60/verify12" and len(set(keys)) == len(keys) == 14 + 11 * 24 + 14 * 12  # keys are unique
    # Verification poses are the sphere's, none a calibration pose's orientation.
    gravity = np.array([p.gravity_fixture for p in plan.verification_poses])
    cosines = gravity @ np.array([p.gravity_fixture for p in plan.poses]).T
    assert len(gravity) == 12 and np.degrees(np.arccos(np.max(cosines))) > 4  # the nearest is 4.4° from a Table 1 pose


def test_ramp_plan_soaks_at_the_ends_and_measures_on_the_software_ramp_in_between() -> None:
    plan = prepare(REPO / "procedures" / "paper-24pos-ramp.yaml").plan
    first, second, third, last = plan.stages[0], plan.stages[1], plan.stages[2], plan.stages[-1]
    setpoints = plan.setpoints_c
    # The first soaks and takes its poses and checks at rest; the ramp leaves once they are taken.
    assert first.entry == first.restart_entry == (Ramp(setpoints[0]), Soak(f"T{setpoints[0]:g}/soak", setpoints[0]))
    assert second.entry == (StartSoftwareRamp(setpoints[0], setpoints[-1]),
                            RampSegment(setpoints[1], 0.5 * (setpoints[0] + setpoints[1])))
    # Later setpoints ride on the ramp; their poses begin half-way from the previous setpoint.
    assert third.entry == (RampSegment(setpoints[2], 0.5 * (setpoints[1] + setpoints[2])),)
    assert [type(s) for s in second.restart_entry] == [Ramp, Soak, StartSoftwareRamp]
    assert last.entry == (RampSegment(setpoints[-1], setpoints[-1]), Soak(f"T{setpoints[-1]:g}/soak", setpoints[-1]))
    assert [type(s) for s in last.restart_entry] == [Ramp, Soak]
    assert [type(s) for s in second.body] == [AdvanceRamp, MeasurePose] * len(plan.poses)
    # The stored plan still lists a soak and the poses for every setpoint (a resumed run may soak at any).
    assert [s.key for s in second.records][:2] == [f"T{setpoints[1]:g}/soak", f"T{setpoints[1]:g}/pose01"]


def test_a_bidirectional_ramp_turns_at_the_last_setpoint_and_measures_half_way_between_on_the_way_back() -> None:
    prepared = prepare(REPO / "procedures" / "fast-bidirectional-ramp.yaml")
    plan = prepared.plan
    down = [60.0, 50.0, 40.0, 30.0, 20.0, 10.0, 0.0, -10.0, -20.0, -30.0, -40.0]
    assert list(plan.setpoints_c) == down + [-35.0, -25.0, -15.0, -5.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0]
    stages = {stage.setpoint_c: stage for stage in plan.stages}
    assert stages[60.0].entry == (Ramp(60.0), Soak("T60/soak", 60.0))  # at rest until its poses are taken
    assert stages[50.0].entry == (StartSoftwareRamp(60.0, -40.0), RampSegment(50.0, 55.0))
    assert stages[-40.0].entry == (RampSegment(-40.0, -40.0), Soak("T-40/soak", -40.0))  # the turn soaks
    assert stages[-35.0].entry == (StartSoftwareRamp(-40.0, 55.0), RampSegment(-35.0, -37.5))  # then back
    assert stages[-25.0].entry == (RampSegment(-25.0, -30.0),)
    assert stages[-25.0].restart_entry[-1] == StartSoftwareRamp(-25.0, 55.0)  # a resumed run goes on up
    assert stages[55.0].entry == (RampSegment(55.0, 55.0),)  # the last band is taken where the ramp stops
    keys = [s.key for s in plan.records]
    assert len(set(keys)) == len(keys) and "T-35/pose01" in keys
    verified = sorted({k.split("/")[0] for k in keys if "/verify" in k})
    assert verified == ["T-40", "T60"]  # verify.on_ramp: false: at rest only, where the DUTs were soaked
    for soaked in ("T60", "T-40"):  # the checks before the calibration poses: the DUTs still creep towards the
        order = [k.split("/")[1][:4] for k in keys if k.startswith(f"{soaked}/") and "/soak" not in k]  # air there
        assert order == sorted(order, key=lambda kind: kind != "veri") and "pose" in order, order
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, plan)
    assert [r.soak_outcome for r in estimate.setpoints].count("stable") == 2  # the start and the turn only


def test_the_imu_fast_method_turns_rate_steps_in_every_band_and_records_noise_only_where_soaked() -> None:
    """procedures/imu-fast.yaml: in each band each way, the ramp's setpoint written before every pose and every
    rate step (30: five rates both ways about three axes); the still noise record and the verification rates
    only where the DUTs were soaked (the start and the turn); `rig plan` times every step."""
    prepared = prepare(REPO / "procedures" / "imu-fast.yaml")
    plan = prepared.plan
    stages = {stage.setpoint_c: stage for stage in plan.stages}
    for setpoint in (50.0, -25.0):
        body = stages[setpoint].body
        steps = body[1::2]
        assert all(isinstance(step, AdvanceRamp) for step in body[0::2])
        assert [type(s) for s in steps[:12]] == [MeasurePose] * 12
        assert [type(s) for s in steps[12:]].count(RateStep) == 30   # the table stopped between the axes
    keys = [s.key for s in plan.records]
    assert sorted({k.split("/")[0] for k in keys if "/noise" in k}) == ["T-40", "T60"]
    assert sorted({k.split("/")[0] for k in keys if "/verify" in k}) == ["T-40", "T60"]
    estimate = estimate_duration(prepared.procedure.model, prepared.rig.model, plan)
    assert 3.0 < estimate.total_s / 3600 < 6.0   # sixteen IMUs in one cycle: the issue's ≤ 6 h of rig time


def test_cooldown_plan_soaks_once_then_numbers_its_records_at_the_held_pose() -> None:
    plan = prepare(REPO / "procedures" / "cooldown-60c.yaml").plan
    (stage,) = plan.stages
    assert [type(s) for s in stage.entry] == [Ramp, Soak]
    assert all(isinstance(s, CooldownRecord) and s.pose == plan.poses[0] for s in stage.body)
    assert [s.number for s in stage.body] == list(range(1, len(stage.body) + 1))
    assert stage.body[0].key.endswith("/cool0001")


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


def test_a_verification_pose_the_fit_would_see_is_refused(write) -> None:
    from accelcal_rig.errors import ConfigError
    from tests.conftest import TINY_PROCEDURE

    text = TINY_PROCEDURE + "verify: {schedule: {kind: six-position}}\n"
    with pytest.raises(ConfigError, match=r"tiny.yaml:\d+: verify.schedule: verification pose 1 has the orientation "
                                          r"of calibration pose 1"):
        prepare(write("tiny.yaml", text))


def travel_s(poses, speeds_deg_s: np.ndarray) -> float:
    """The table's travel through the poses in order from zero, its slowest axis at each move."""
    path = np.array([np.zeros(len(speeds_deg_s))] + [p.angles_deg for p in poses])
    return float(np.sum(np.max(np.abs(np.diff(path, axis=0)) / speeds_deg_s, axis=1)))


def test_shortest_travel_visits_every_pose_once_each_keeping_its_number_and_direction_in_less_travel() -> None:
    from accelcal_rig.config.load import load_rig
    from accelcal_rig.config.schedule import SphereSchedule
    from accelcal_rig.plan.compile import compile_poses
    from tests.conftest import SIM_RIG

    rig = load_rig(SIM_RIG).model
    speeds = np.array([a.speed_deg_s for a in rig.turntable.axes])
    listed = compile_poses(SphereSchedule(kind="sphere", count=12), rig)
    ordered = compile_poses(SphereSchedule(kind="sphere", count=12, order="shortest-travel"), rig)
    assert [p.number for p in listed] == list(range(1, 13))
    assert sorted(p.number for p in ordered) == list(range(1, 13)) and [p.number for p in ordered] != list(range(1, 13))
    by_number = {p.number: p for p in listed}
    kinematics = TurntableKinematics(rig.turntable.axes)
    for pose in ordered:  # the same direction under its number, reached by the angles given
        np.testing.assert_allclose(pose.gravity_fixture, by_number[pose.number].gravity_fixture, atol=1e-12)
        np.testing.assert_allclose(kinematics.gravity_in_fixture(np.array(pose.angles_deg)), pose.gravity_fixture,
                                   atol=1e-6)
    assert travel_s(ordered, speeds) < 0.5 * travel_s(listed, speeds)


def test_shortest_travel_refuses_a_schedule_too_long_to_order() -> None:
    from pydantic import ValidationError

    from accelcal_rig.config.schedule import MAX_ORDERED_POSES, SphereSchedule

    with pytest.raises(ValidationError, match="shortest-travel orders at most"):
        SphereSchedule(kind="sphere", count=MAX_ORDERED_POSES + 1, order="shortest-travel")
