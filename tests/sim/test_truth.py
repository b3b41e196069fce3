import numpy as np

from accelcal_rig.sim.truth import fixture_parameters_at, truth_for_serial


def test_truth_is_fixed_by_the_serial_number() -> None:
    a, b = truth_for_serial("SN-1"), truth_for_serial("SN-1")
    np.testing.assert_array_equal(a.coefficients, b.coefficients)
    assert not np.allclose(a.coefficients, truth_for_serial("SN-2").coefficients)


def test_magnitudes_are_those_of_the_papers_part() -> None:
    for serial in (f"SN-{i}" for i in range(20)):
        truth = truth_for_serial(serial)
        at_25 = truth.parameters_at(25.0)
        assert np.all(np.abs(at_25[0:3]) <= 25e-3)                     # bias within ±25 mg
        assert np.all(np.abs(at_25[3:6] - 1) <= 0.01)                  # scale within ±1 %
        assert np.all(np.abs(np.degrees(at_25[6:12])) <= 0.5)          # tenths of a degree
        curve = truth.parameters_at(np.linspace(-40, 60, 201))
        bias_drift = curve[:, 0:3].max(axis=0) - curve[:, 0:3].min(axis=0)
        assert np.all((bias_drift >= 10e-3 - 1e-12) & (bias_drift <= 20e-3 + 1e-12))  # 10–20 mg drift


def test_parameters_at_broadcasts_over_temperatures() -> None:
    truth = truth_for_serial("SN-1")
    assert truth.parameters_at(np.zeros((4, 5))).shape == (4, 5, 12)


def test_a_fixture_evaluated_at_once_gives_each_dut_its_own_parameters() -> None:
    truths = [truth_for_serial(f"SN-{k}") for k in range(5)]
    temperature_c = np.array([-40.0, -3.5, 25.0, 41.2, 60.0])
    together = fixture_parameters_at(np.stack([t.coefficients for t in truths]), temperature_c)
    np.testing.assert_allclose(together, [t.parameters_at(c) for t, c in zip(truths, temperature_c)], rtol=0, atol=1e-15)
