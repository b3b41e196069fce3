"""Allan deviation and the noise figures read off it: the deviations against the published values of the
NBS14 1000-point data set (NIST SP 1065, Table 31, p. 108: generated here, as the handbook gives its
generator), and the random walk and bias instability against simulated noise of known density and flicker."""

from __future__ import annotations

import numpy as np
import pytest
from allantools.noise_kasdin import Noise

from accelcal_rig.fit.allan import FLICKER_FLOOR, allan_deviation, bias_instability, per_root_hour, random_walk

#: NIST SP 1065 (Riley 2008), Table 31: the NBS14 1000-point data set's overlapping Allan deviation at τ = 1,
#: 10 and 100 (frequency data, τ0 = 1).
NBS14_OADEV = (2.922319e-01, 9.159953e-02, 3.241343e-02)


def nbs14_1000() -> np.ndarray:
    """The NBS14 1000-point frequency data: n(i+1) = 16807·n(i) mod (2³¹ − 1) from 1234567890, over 2³¹ − 1
    (NIST SP 1065, §12.3)."""
    n = [1234567890]
    for _ in range(999):
        n.append((16807 * n[-1]) % 2147483647)
    assert n[1:4] == [395529916, 1209410747, 633705974]  # the first three, as the handbook prints them
    return np.array(n, dtype=float) / 2147483647


def test_the_nbs14_data_sets_overlapping_allan_deviation_is_the_published_one() -> None:
    (curve,) = allan_deviation(nbs14_1000(), 1.0, taus=np.array([1.0, 10.0, 100.0]))
    np.testing.assert_allclose(curve.tau_s, [1.0, 10.0, 100.0])
    np.testing.assert_allclose(curve.deviation, NBS14_OADEV, rtol=1e-6)


def test_white_noise_of_known_density_gives_it_back_within_its_interval() -> None:
    """Three axes of white noise: each density within 1 % and inside its 99.7 % interval (the 68 % one
    misses one axis in three, as it should)."""
    fs, density = 100.0, 0.01  # e.g. 0.01 °/s/√Hz: an angle random walk of 0.6 °/√h
    samples = np.random.default_rng(1).normal(0.0, density * np.sqrt(fs), (200_000, 3))
    for curve in allan_deviation(samples, fs):
        walk = random_walk(curve, confidence=0.997)  # three axes: within 3σ, each
        assert walk.low <= density <= walk.high and walk.value == pytest.approx(density, rel=0.01)
        assert bias_instability(curve).value < 0.05 * density  # no flicker in it: next to nothing
    assert per_root_hour(density) == pytest.approx(0.6)


def test_white_noise_and_flicker_are_told_apart() -> None:
    """Flicker rate noise (Kasdin's discrete flicker FM) of bias instability 0.01 under white noise of density
    0.002, at 100 Hz for 44 min: each figure within 5 % of its truth, the bias instability within its interval."""
    fs, density = 100.0, 0.002
    np.random.seed(3)  # Kasdin's generator draws from numpy's global stream
    flicker = Noise(nr=2**18, qd=1e-8, b=-3)
    flicker.generateNoise()
    truth_b = flicker.adev(1.0 / fs, 1.0) / FLICKER_FLOOR
    rate = np.diff(flicker.time_series) * fs + np.random.default_rng(2).normal(0.0, density * np.sqrt(fs),
                                                                               2**18 - 1)
    (curve,) = allan_deviation(rate, fs)
    walk, instability = random_walk(curve), bias_instability(curve, confidence=0.95)
    assert walk.value == pytest.approx(density, rel=0.05)
    assert instability.value == pytest.approx(truth_b, rel=0.05)
    assert instability.low <= truth_b <= instability.high


def test_too_short_a_record_is_refused() -> None:
    with pytest.raises(ValueError, match="at least 16"):
        allan_deviation(np.zeros((8, 3)), 100.0)
