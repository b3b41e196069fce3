import numpy as np
import pytest

from accelcal_rig.fit.thermal import fit_thermal
from accelcal_rig.sim.truth import truth_for_serial

TEMPERATURES = np.arange(-40.0, 61.0, 10.0)
FREE = np.ones(12, dtype=bool)


def test_cubic_truth_is_recovered_exactly_in_the_scaled_variable() -> None:
    truth = truth_for_serial("TH-1")
    model = fit_thermal(TEMPERATURES, truth.parameters_at(TEMPERATURES), np.full((11, 12), 1e-5), FREE, 3)
    between = np.linspace(-40, 60, 37)
    np.testing.assert_allclose(model.parameters_at(between), truth.parameters_at(between), atol=1e-12)
    assert model.domain_c == (-40.0, 60.0)
    np.testing.assert_allclose(model.scaled(np.array([-40.0, 10.0, 60.0])), [-1, 0, 1])
    np.testing.assert_allclose(model.residuals, 0.0, atol=1e-12)
    assert model.warnings == []


def test_residuals_are_kept_when_the_data_are_not_a_polynomial() -> None:
    values = np.zeros((11, 12))
    values[:, 0] = np.sin(TEMPERATURES / 10.0)
    model = fit_thermal(TEMPERATURES, values, np.full((11, 12), 1e-5), FREE, 3)
    assert np.abs(model.residuals[:, 0]).max() > 0.1
    np.testing.assert_allclose(model.residuals[:, 0], values[:, 0] - model.parameters_at(TEMPERATURES)[:, 0])


def test_too_few_temperatures_lower_the_degree_with_a_warning() -> None:
    model = fit_thermal(np.array([0.0, 20.0]), np.ones((2, 12)), np.full((2, 12), 1e-5), FREE, 3)
    assert any("degree 1 used" in w for w in model.warnings)
    exact = fit_thermal(np.array([0.0, 10.0, 20.0, 30.0]), np.ones((4, 12)), np.full((4, 12), 1e-5), FREE, 3)
    assert any("interpolates" in w for w in exact.warnings)


def test_clamp_holds_the_edge_value_extrapolate_follows_the_curve() -> None:
    values = np.zeros((11, 12))
    values[:, 0] = (TEMPERATURES / 50.0) ** 2
    model = fit_thermal(TEMPERATURES, values, np.full((11, 12), 1e-5), FREE, 2)
    assert model.parameters_at(80.0, "clamp")[0] == pytest.approx(model.parameters_at(60.0)[0])
    assert model.parameters_at(80.0, "extrapolate")[0] == pytest.approx((80 / 50) ** 2)


def test_fixed_parameters_stay_constant() -> None:
    free = FREE.copy()
    free[9:12] = False
    values = np.tile(np.arange(12.0), (11, 1))
    values[:, 9:12] = 0.0
    model = fit_thermal(TEMPERATURES, values, np.full((11, 12), 1e-5), free, 3)
    np.testing.assert_allclose(model.parameters_at(TEMPERATURES)[:, 9:12], 0.0)
