"""The simulated table's path through a block of samples is where it stands at each of their times, sample by
sample: a move, a rate step's ramp and its constant rate."""

from __future__ import annotations

import numpy as np

from accelcal_rig.sim.turntable_motion import TurntableMotion


def test_the_path_through_a_block_is_the_table_at_each_samples_time() -> None:
    motion = TurntableMotion(np.array([20.0, 10.0]), 0.0, 0.5, np.random.default_rng(0))
    motion.command(0.0, np.array([30.0, -15.0]))     # both axes travel, the second arrives later
    motion.rotate(1.0, 0, 100.0, 50.0)               # then the first ramps to a rate and holds it
    times = np.linspace(0.0, 5.0, 501)
    angles, rates = motion.path_deg(times)
    np.testing.assert_allclose(angles, np.array([motion.position_deg(t) for t in times]), atol=1e-9)
    np.testing.assert_allclose(rates, np.array([motion.rate_deg_s(t) for t in times]), atol=1e-9)
    assert rates[-1, 0] == 100.0 and rates[-1, 1] == 0.0 and 0.0 < rates[150, 0] < 100.0
