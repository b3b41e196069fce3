import numpy as np
import pytest

from accelcal_rig.config.rig import TurntableAxis
from accelcal_rig.plan import schedules
from accelcal_rig.plan.kinematics import TurntableKinematics, UnreachablePose


def gimbal(middle_limits: tuple[float, float] | None = None) -> TurntableKinematics:
    middle = (
        TurntableAxis(name="middle", axis=(1, 0, 0), min_deg=-180, max_deg=180, continuous=True)
        if middle_limits is None
        else TurntableAxis(name="middle", axis=(1, 0, 0), min_deg=middle_limits[0], max_deg=middle_limits[1])
    )
    return TurntableKinematics([
        TurntableAxis(name="outer", axis=(0, 0, 1), min_deg=-180, max_deg=180, continuous=True),
        middle,
        TurntableAxis(name="inner", axis=(0, 0, 1), min_deg=-180, max_deg=180, continuous=True),
    ])


def test_zero_angles_leave_gravity_along_fixture_z() -> None:
    np.testing.assert_allclose(gimbal().gravity_in_fixture(np.zeros(3)), [0, 0, 1], atol=1e-15)


def test_tilting_the_middle_axis_by_90_puts_gravity_on_y() -> None:
    # Tilting the platform +90° about world x raises its +y axis to point up.
    np.testing.assert_allclose(gimbal().gravity_in_fixture(np.array([0, 90, 0])), [0, 1, 0], atol=1e-12)


def test_outer_vertical_axis_does_not_change_gravity() -> None:
    k = gimbal()
    np.testing.assert_allclose(k.gravity_in_fixture(np.array([73.0, 30, 10])),
                               k.gravity_in_fixture(np.array([0.0, 30, 10])), atol=1e-12)


def test_forward_kinematics_is_vectorised() -> None:
    k = gimbal()
    angles = np.random.default_rng(0).uniform(-180, 180, (5, 4, 3))
    stacked = k.gravity_in_fixture(angles)
    assert stacked.shape == (5, 4, 3)
    np.testing.assert_allclose(stacked[2, 3], k.gravity_in_fixture(angles[2, 3]))


def test_inverse_kinematics_reaches_every_sphere_direction() -> None:
    k = gimbal()
    current = np.zeros(3)
    for direction in schedules.sphere(60):
        current = k.solve(direction, current)
        np.testing.assert_allclose(k.gravity_in_fixture(current), direction, atol=1e-8)
        assert np.all((current >= -180) & (current < 180))


def test_inverse_kinematics_prefers_least_travel() -> None:
    k = gimbal()
    angles = k.solve(np.array([0, 1.0, 0]), np.zeros(3))
    np.testing.assert_allclose(angles, [0, 90, 0], atol=1e-6)


def test_limited_axis_makes_the_lower_hemisphere_unreachable() -> None:
    k = gimbal(middle_limits=(-90, 90))
    angles = k.solve(np.array([0.8, 0, 0.6]), np.zeros(3))  # tilted 53° is still in reach
    assert -90 <= angles[1] <= 90
    with pytest.raises(UnreachablePose, match="out of reach"):
        k.solve(np.array([0, 0, -1.0]), np.zeros(3))


def test_wrap_keeps_continuous_axes_in_range_only() -> None:
    k = gimbal(middle_limits=(-90, 90))
    np.testing.assert_allclose(k.wrap(np.array([190.0, 80.0, -540.0])), [-170.0, 80.0, -180.0])


def test_a_two_axis_table_says_what_its_geometry_reaches() -> None:
    """A vertical axis and a horizontal one turn gravity in the fixture frame about the horizontal axis only:
    the fixture directions 90° from it, a great circle. A direction off it is refused by the geometry, in one
    line saying which circle and how far off; one on it is reached."""
    axes = (TurntableAxis(name="outer", axis=(0, 0, 1), min_deg=-180, max_deg=180, continuous=True),
            TurntableAxis(name="middle", axis=(1, 0, 0), min_deg=-180, max_deg=180, continuous=True))
    kinematics = TurntableKinematics(axes)
    angles = kinematics.solve(np.array([0.0, 0.6, 0.8]), np.zeros(2))
    np.testing.assert_allclose(kinematics.gravity_in_fixture(angles), [0.0, 0.6, 0.8], atol=1e-9)
    with pytest.raises(UnreachablePose, match=r"turntable's geometry: its two axes \(outer vertical, middle about "
                                              r"\[1.0, 0.0, 0.0\]\) bring only fixture directions 90° from the middle "
                                              r"axis to gravity; this one is 45.0° off that circle"):
        kinematics.solve(np.array([1.0, 1.0, 0.0]) / np.sqrt(2), np.zeros(2))


def test_an_axis_turns_the_fixture_about_a_direction_its_inner_axes_choose() -> None:
    """A horizontal outer axis turns the fixture about any direction square to the inner axis (the inner axis
    chooses which); the innermost turns it about its own direction only, whatever the angles."""
    axes = (TurntableAxis(name="roll", axis=(1, 0, 0), min_deg=-180, max_deg=180, continuous=True),
            TurntableAxis(name="spin", axis=(0, 0, 1), min_deg=-180, max_deg=180, continuous=True))
    kinematics = TurntableKinematics(axes)
    for target in ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-0.6, 0.8, 0.0]):
        angles = kinematics.solve_turn(0, np.array(target), np.array([40.0, 10.0]))
        assert angles[0] == pytest.approx(40.0)                   # the turning axis is left where it was
        np.testing.assert_allclose(kinematics.angular_velocity_in_fixture(angles, np.array([1.0, 0.0])), target,
                                   atol=1e-8)
    np.testing.assert_allclose(kinematics.solve_turn(1, np.array([0.0, 0.0, 1.0]), np.array([40.0, 10.0])),
                               [40.0, 10.0])
    for unreachable in ((0, [0.0, 0.0, 1.0]), (1, [1.0, 0.0, 0.0])):
        with pytest.raises(UnreachablePose):
            kinematics.solve_turn(unreachable[0], np.array(unreachable[1]), np.zeros(2))
