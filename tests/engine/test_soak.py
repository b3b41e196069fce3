import numpy as np
import pytest

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


SETTLING = SoakCriterion(criterion="settling", min_dwell_min=5, window_min=20, settle_c=0.1, max_rate_c_per_min=0.02,
                         chamber_tolerance_c=1.0, poll_s=10, timeout_min=240)


def first_order_readings(t_s: np.ndarray, tau_s: np.ndarray, seed: int, start_c: float = 20.0,
                         end_c: float = 30.0) -> np.ndarray:
    """DUTs approaching `end_c` with their time constants, read with noise in the ADXL355's 0.11 °C steps."""
    rng = np.random.default_rng(seed)
    true = end_c + (start_c - end_c) * np.exp(-t_s[:, None] / tau_s[None, :])
    return np.round((true + rng.normal(0, 0.05, true.shape)) / 0.11) * 0.11


def test_the_settling_fit_finds_the_fixtures_time_constant_and_what_is_left_of_the_approach() -> None:
    from accelcal_rig.engine.soak import fit_settling

    t = np.arange(0.0, 40 * 60 + 1, 10.0)
    tau = np.array([540.0, 600.0, 660.0])  # a fixture's DUTs: ±10 % of 10 min
    readings = first_order_readings(t, tau, seed=2)
    window_start = int(np.searchsorted(t, t[-1] - 10 * 60))  # half of it shorter than τ: the soak's τ is kept
    settling = fit_settling(SETTLING, t, readings, window_start)
    assert np.all(np.abs(settling.time_constant_s - tau) < 0.2 * tau)
    left = 10.0 * np.exp(-t[-1] / tau)  # the truth: 0.1…0.2 °C still to come after 40 min
    assert np.all(settling.remaining_c >= left - 0.02)  # a bound (k = 2), not below what is left
    assert np.all(settling.remaining_c <= left + 0.12)
    np.testing.assert_allclose(settling.now_c, 30.0 - left, atol=0.06)


def stable_after_s(criterion: SoakCriterion, poll_s: float, seed: int, n_duts: int) -> float:
    from accelcal_rig.engine.soak import first_stable_poll

    t = np.arange(0.0, criterion.timeout_min * 60 + 1, poll_s)
    tau = np.random.default_rng(seed).uniform(540.0, 660.0, n_duts)
    k = first_stable_poll(criterion, 30.0, 0.0, t, np.full(len(t), 30.0), first_order_readings(t, tau, seed))
    assert k is not None
    return float(t[k])


def test_the_settling_criterion_does_not_depend_on_the_poll_rate_or_the_fixture_size_as_the_band_does() -> None:
    """The band's span of noisy readings widens with more of them: a 10 s poll or a larger fixture holds
    the soak open longer. The settling fit's bounds only narrow with more readings."""
    band = SETTLING.model_copy(update={"criterion": "band", "band_c": 0.3, "window_min": 10})
    seeds = range(6)

    def median_s(criterion: SoakCriterion, poll_s: float, n_duts: int) -> float:
        return float(np.median([stable_after_s(criterion, poll_s, seed, n_duts) for seed in seeds]))

    assert median_s(band, 10, 16) > 1.3 * median_s(band, 30, 4)  # the band: longer, the more readings
    settling_fast, settling_slow = median_s(SETTLING, 10, 16), median_s(SETTLING, 30, 4)
    assert abs(settling_fast - settling_slow) < 0.15 * settling_slow


def test_a_settling_soak_judged_poll_by_poll_agrees_with_the_estimates_judgement() -> None:
    from accelcal_rig.engine.soak import first_stable_poll, settled_at

    t = np.arange(0.0, 120 * 60 + 1, 30.0)
    readings = first_order_readings(t, np.array([500.0, 700.0]), seed=5)
    detector, found = SoakDetector(SETTLING, 30.0, 0.0), None
    for k in range(len(t)):
        detector.add(t[k], 30.0, readings[k])
        if detector.is_stable():
            found = k
            break
    assert found is not None and first_stable_poll(SETTLING, 30.0, 0.0, t, np.full(len(t), 30.0), readings) == found
    np.testing.assert_allclose(settled_at(SETTLING, t, readings, found), detector.settled_dut_c())
    assert abs(detector.settled_dut_c() - 30.0).max() < 0.15  # where they settled, not the window's lagging mean


def test_a_dry_run_soaks_by_the_settling_criterion_and_says_how_settled(write, workdir) -> None:
    import h5py

    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare
    from tests.conftest import TINY_PROCEDURE

    text = TINY_PROCEDURE.replace("soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}",
                                  "soak: {criterion: settling, min_dwell_min: 5, window_min: 10, poll_s: 10, "
                                  "timeout_min: 120}")
    result = run_campaign(prepare(write("settle.yaml", text)), workdir / "s.h5", dry_run=True, seed=1,
                          overwrite=False, calibration=None)
    assert result.summary.state == "done"
    with h5py.File(workdir / "s.h5", "r") as f:
        messages = [m.decode() for m in f["events/message"][:]]
        soak = f["soaks/T30"]
        settled, last = soak["settled_dut_c"][:], soak["dut_c"][-20:].mean(axis=0)
    assert any("stable after" in m and "still to come ≤" in m and "°C/min" in m for m in messages)
    assert np.all(np.abs(settled - last) < 0.15)


@pytest.mark.parametrize("trend", ["drift", "wobble", "slow mode"])
def test_a_settling_fit_is_not_fooled_by_what_its_curve_would_not_follow(trend: str) -> None:
    """A fast approach, then within the window: a drift of 2.5 × the rate allowed, a 0.5 °C wobble, or a
    second, slow mode: none of these is settled."""
    from accelcal_rig.engine.soak import fit_settling

    criterion = SETTLING.model_copy(update={"window_min": 10})
    t = np.arange(0.0, 60 * 60 + 1, 30.0)
    fast = 30.0 - 10.0 * np.exp(-t / 180.0)
    extra = {"drift": 0.05 / 60 * t, "wobble": 0.5 * np.sin(2 * np.pi * t / 1200.0),
             "slow mode": -3.0 * np.exp(-t / 3000.0)}[trend]
    readings = (fast + extra)[:, None]
    window_start = int(np.searchsorted(t, t[-1] - 600))
    assert not fit_settling(criterion, t, readings, window_start).settled(criterion)


def test_too_few_polls_in_the_window_are_never_settled_and_such_a_window_is_refused() -> None:
    from accelcal_rig.engine.soak import fit_settling

    t = np.arange(0.0, 3600.0, 600.0)
    flat = np.full((len(t), 2), 30.0)
    assert not fit_settling(SETTLING, t, flat, len(t) - 2).settled(SETTLING)  # two polls: nothing is known
    with pytest.raises(ValueError, match="at least 5 polls in the window"):
        SoakCriterion(criterion="settling", window_min=5, poll_s=600, min_dwell_min=0)


def test_the_quick_rejection_of_a_moving_window_judges_every_poll_as_the_full_settling_fit_does() -> None:
    from accelcal_rig.engine.soak import MIN_WINDOW_POLLS, fit_settling, is_settled

    t = np.arange(0.0, 90 * 60 + 1, 30.0)
    readings = first_order_readings(t, np.array([540.0, 600.0, 900.0]), seed=5)
    verdicts = []
    for k in range(MIN_WINDOW_POLLS, len(t)):
        start = int(np.searchsorted(t[:k + 1], t[k] - SETTLING.window_min * 60.0))
        full = fit_settling(SETTLING, t[:k + 1], readings[:k + 1], start).settled(SETTLING)
        assert is_settled(SETTLING, t[:k + 1], readings[:k + 1], start) == full, f"poll {k}"
        verdicts.append(full)
    assert not verdicts[0] and verdicts[-1]  # both verdicts were judged
