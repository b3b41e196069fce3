import numpy as np

from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS, correct, distort, error_matrix


def random_parameters(rng: np.random.Generator, shape: tuple[int, ...] = ()) -> np.ndarray:
    return IDENTITY_PARAMETERS + rng.normal(0, 0.01, shape + (12,))


def test_identity_parameters_change_nothing() -> None:
    g = np.random.default_rng(0).normal(size=(10, 3))
    np.testing.assert_allclose(correct(g, IDENTITY_PARAMETERS), g, atol=1e-15)


def test_correct_inverts_distort_for_batches_of_parameters() -> None:
    rng = np.random.default_rng(1)
    params = random_parameters(rng, (7,))
    g = rng.normal(size=(7, 3))
    np.testing.assert_allclose(correct(distort(g, params), params), g, atol=1e-13)


def test_matrix_is_a_rotation_times_a_lower_triangular_scale() -> None:
    params = random_parameters(np.random.default_rng(2))
    without_misalignment = params.copy()
    without_misalignment[9:12] = 0.0
    cs = error_matrix(without_misalignment)          # C·S alone: lower triangular, scale on the diagonal
    np.testing.assert_allclose(np.triu(cs, 1), 0.0, atol=1e-15)
    np.testing.assert_allclose(np.diag(cs), params[3:6], atol=1e-15)
    m = error_matrix(params) @ np.linalg.inv(cs)     # what remains is M: a proper rotation
    np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(m) > 0


def test_bias_is_subtracted_before_the_matrix() -> None:
    params = IDENTITY_PARAMETERS.copy()
    params[0:3] = [0.01, -0.02, 0.03]
    params[3:6] = 2.0
    np.testing.assert_allclose(correct(np.array([0.01, -0.02, 1.03]), params), [0, 0, 2.0], atol=1e-15)
