"""Schedule geometry against the paper's Table 1 and basic properties of the others."""

import numpy as np

from accelcal_rig.plan import schedules


def test_paper_24_is_three_circles_of_eight_45_degree_steps() -> None:
    directions = schedules.paper_24()
    assert directions.shape == (24, 3)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0)
    for block, fixed_axis in zip(range(3), (2, 1, 0)):  # rows 1–8 keep z, 9–16 keep y, 17–24 keep x
        circle = directions[8 * block: 8 * block + 8]
        np.testing.assert_allclose(circle[:, fixed_axis], 0.0, atol=1e-12)
        steps = np.degrees(np.arccos(np.clip(np.sum(circle * np.roll(circle, -1, axis=0), axis=1), -1, 1)))
        np.testing.assert_allclose(steps, 45.0, atol=1e-9)


def test_paper_24_starting_positions_follow_table_1() -> None:
    directions = schedules.paper_24()
    np.testing.assert_allclose(directions[0], [0, 1, 0], atol=1e-12)   # Py1 vertical
    np.testing.assert_allclose(directions[8], [0, 0, 1], atol=1e-12)   # Pz2 vertical
    np.testing.assert_allclose(directions[16], [0, 0, 1], atol=1e-12)  # Pz3 vertical
    # Each circle passes through both ends of the two axes it turns.
    for block, axes in zip(range(3), ((0, 1), (0, 2), (1, 2))):
        circle = directions[8 * block: 8 * block + 8]
        for axis in axes:
            assert np.isclose(circle[:, axis].max(), 1.0) and np.isclose(circle[:, axis].min(), -1.0)


def test_six_position_has_each_axis_up_and_down() -> None:
    directions = schedules.six_position()
    assert sorted(map(tuple, directions)) == sorted(map(tuple, np.vstack([np.eye(3), -np.eye(3)])))


def test_sphere_is_unit_even_and_deterministic() -> None:
    directions = schedules.sphere(500)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0)
    np.testing.assert_allclose(directions.mean(axis=0), 0.0, atol=0.01)  # no hemisphere favoured
    nearest = np.sort(directions @ directions.T, axis=1)[:, -2]
    spacing = np.degrees(np.arccos(nearest))
    assert spacing.max() / spacing.min() < 2.0  # evenly spread: no clusters, no holes
    np.testing.assert_array_equal(directions, schedules.sphere(500))
