import numpy as np

from accelcal_rig.sim.truth import truth_for_serial


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
