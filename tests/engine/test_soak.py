import numpy as np

from accelcal_rig.config.procedure import SoakCriterion
from accelcal_rig.engine.soak import SoakDetector

CRITERION = SoakCriterion(min_dwell_min=10, window_min=5, band_c=0.3, chamber_tolerance_c=1.0, poll_s=10,
                          timeout_min=60)


def feed(detector: SoakDetector, until_s: float, dut_c, chamber_c=30.0, start_s: float = 0.0) -> None:
    for t in np.arange(start_s, until_s + 1e-9, 10.0):
        detector.add(t, chamber_c(t) if callable(chamber_c) else chamber_c,
                     np.array([f(t) if callable(f) else f for f in dut_c]))


def test_flat_temperatures_are_stable_only_after_the_minimum_dwell() -> None:
    detector = SoakDetector(CRITERION, 30.0, t_reached_s=0.0)
    feed(detector, 590, [30.1, 30.2])
    assert not detector.is_stable()
    feed(detector, 600, [30.1, 30.2], start_s=600)
    assert detector.is_stable()


def test_one_drifting_dut_keeps_the_soak_open() -> None:
    detector = SoakDetector(CRITERION, 30.0, t_reached_s=0.0)
    feed(detector, 1200, [30.1, lambda t: 25 + t / 200])  # 0.05 °C/10 s = 1.5 °C per window
    assert not detector.is_stable()
    np.testing.assert_allclose(detector.dut_spans_c(), [0.0, 1.5])


def test_chamber_outside_tolerance_keeps_the_soak_open() -> None:
    detector = SoakDetector(CRITERION, 30.0, t_reached_s=0.0)
    feed(detector, 1200, [30.1], chamber_c=lambda t: 31.5 if t > 1000 else 30.0)
    assert not detector.is_stable()


def test_settled_temperature_is_the_window_mean() -> None:
    detector = SoakDetector(CRITERION, 30.0, t_reached_s=0.0)
    feed(detector, 1200, [lambda t: 30.0 + 0.1 * ((t // 10) % 2)])
    assert detector.is_stable()
    np.testing.assert_allclose(detector.settled_dut_c(), [30.05], atol=0.01)
