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


def test_the_estimates_vectorised_judgement_agrees_with_the_detector_poll_by_poll() -> None:
    """`first_stable_poll` (the estimate) and `SoakDetector` (the campaign) are one criterion: on random
    soaks with quantised readings, chamber excursions and a deadline cut, the same first stable poll."""
    from accelcal_rig.engine.soak import first_stable_poll, settled_at

    rng = np.random.default_rng(1)
    outcomes = set()
    for _ in range(120):
        poll = float(rng.choice([1, 5, 10, 30]))
        window, dwell = float(rng.integers(1, 20)), float(rng.integers(0, 30))
        timeout = max(window, dwell) + float(rng.integers(1, 60))
        criterion = SoakCriterion(min_dwell_min=dwell, window_min=window, band_c=float(rng.choice([0.1, 0.3, 0.5])),
                                  chamber_tolerance_c=1.0, poll_s=poll, timeout_min=timeout)
        n = int(np.ceil(timeout * 60 / poll)) + 1
        t = np.minimum(100 + poll * np.arange(n), 100 + timeout * 60)
        tau = rng.uniform(100, 2000, int(rng.integers(1, 5)))
        dut = np.round((30 - 5 * np.exp(-(t[:, None] - t[0]) / tau) + rng.normal(0, 0.05, (n, len(tau)))) / 0.11) * 0.11
        air = 30 + rng.normal(0, 0.3, n) + 2 * (t < 100 + rng.uniform(0, 600))
        detector, expected = SoakDetector(criterion, 30.0, 100.0), None
        for k in range(n):
            detector.add(t[k], air[k], dut[k])
            if detector.is_stable():
                expected = k
                break
        assert first_stable_poll(criterion, 30.0, 100.0, t, air, dut) == expected
        if expected is not None:
            np.testing.assert_allclose(settled_at(criterion, t, dut, expected), detector.settled_dut_c())
        outcomes.add(expected is None)
    assert outcomes == {True, False}  # both stable and never-stable soaks were tried
