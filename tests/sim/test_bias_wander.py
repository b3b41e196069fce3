"""The simulated gyroscope's bias instability: its Allan deviation is flat at 0.664 × B over 1 … 1000 s, its
Gauss–Markov parts have the limits they should, and B = 0 draws nothing."""

from __future__ import annotations

import numpy as np

from accelcal_rig.fit.allan import FLICKER_FLOOR, allan_deviation
from accelcal_rig.sim.bias_wander import BiasWander, gauss_markov_avar


def test_the_allan_floor_is_the_bias_instability() -> None:
    bias_instability = 4.0 / 3600.0                       # 4 °/h in °/s
    wander = BiasWander(bias_instability, np.random.default_rng(1))
    samples = wander.at(np.arange(0.0, 40_000.0, 0.1))    # 11 h at 10 Hz
    for curve in allan_deviation(samples, 10.0):
        floor = (curve.tau_s >= 1.0) & (curve.tau_s <= 1000.0)
        ratio = curve.deviation[floor] / (FLICKER_FLOOR * bias_instability)
        assert np.all((ratio > 0.7) & (ratio < 1.3)), ratio   # flat within the scatter of an 11 h record
        assert curve.deviation[0] < 0.8 * FLICKER_FLOOR * bias_instability   # no white noise of its own


def test_a_gauss_markov_allan_variance_has_its_limits() -> None:
    """Short τ: a random walk's 2σ²τ/3T; long τ: white noise's 2σ²T/τ."""
    assert abs(gauss_markov_avar(np.array([1e-4]), 1.0, 10.0)[0] / (2.0 * 1e-5 / 3.0) - 1.0) < 1e-9
    long = gauss_markov_avar(np.array([1e5]), 1.0, 10.0)[0]
    assert abs(long / (2.0 * 10.0 / 1e5) - 1.0) < 1e-3


def test_no_bias_instability_draws_nothing() -> None:
    rng = np.random.default_rng(5)
    state = rng.bit_generator.state
    assert not BiasWander(0.0, rng).at(np.arange(100.0)).any()
    assert rng.bit_generator.state == state


def test_a_block_at_one_rate_is_the_same_wander_as_steps_one_instant_at_a_time() -> None:
    """The filter that runs a block at one rate (what each FIFO read asks for) gives the numbers the step-by-step
    recursion gives from the same stream, and leaves the same state for the next block."""
    def blocks(one_at_a_time: bool) -> np.ndarray:
        wander = BiasWander(5.0 / 3600.0, np.random.default_rng(11))
        out = []
        for start in (0.0, 2.5, 3600.0):
            t = start + np.arange(200) / 100.0
            out.append(np.concatenate([wander.at(t[i:i + 1]) for i in range(len(t))]) if one_at_a_time
                       else wander.at(t))
        return np.concatenate(out)

    np.testing.assert_allclose(blocks(False), blocks(True), rtol=1e-9, atol=1e-12)  # the wander is ~1e-3 °/s
