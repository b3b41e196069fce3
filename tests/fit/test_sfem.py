import numpy as np

from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS, correct, correct_jacobian, distort, error_matrix


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


def test_the_jacobian_of_correct_is_its_derivative_by_every_parameter() -> None:
    rng = np.random.default_rng(4)
    params = random_parameters(rng, (20,))
    raw = rng.normal(size=(20, 3))
    step = 1e-6
    numeric = np.stack([(correct(raw, params + step * e) - correct(raw, params - step * e)) / (2 * step)
                        for e in np.eye(12)], axis=-1)
    jacobian = correct_jacobian(raw, params)
    assert jacobian.shape == (20, 3, 12)
    np.testing.assert_allclose(jacobian, numeric, atol=1e-8)
    # It broadcasts as correct does: one parameter set for many readings.
    np.testing.assert_allclose(correct_jacobian(raw, params[0]), correct_jacobian(raw, np.tile(params[0], (20, 1))),
                               atol=1e-15)
