"""A gyroscope's bias instability for the simulation: flicker-like wander of the bias as a sum of first-order
Gauss–Markov processes a decade apart in correlation time, their common size set so the Allan deviation's
floor over 1…1000 s is 0.664 × B (the floor flicker noise of bias instability B has: IEEE Std 952, Annex C).

Each process evolves exactly between the instants it is asked for (x ← x·e^(−Δt/T) + s·√(1 − e^(−2Δt/T))·w),
so the wander is the same whatever the sampling, and a DUT's stream draws nothing when B is zero. A block of
samples at one rate (what a FIFO holds) is that recursion with one coefficient per process, run as a linear
filter (scipy's lfilter) instead of a step at a time: the same numbers, one normal draw per instant as before.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from accelcal_rig.fit.allan import FLICKER_FLOOR

#: Correlation times of the processes, s: the floor is flat within about 1…1000 s.
CORRELATION_TIMES_S = np.array([0.5, 5.0, 50.0, 500.0])
#: Averaging times the floor is set over.
_FLOOR_TAUS_S = np.geomspace(1.0, 1000.0, 31)


def gauss_markov_avar(tau_s: np.ndarray, variance: float, correlation_s: float) -> np.ndarray:
    """The Allan variance of a first-order Gauss–Markov process of this variance and correlation time T
    (IEEE Std 952, Annex C): (2σ²/r)·(1 − (3 − 4e^(−r) + e^(−2r)) / 2r), r = τ/T; 2σ²r/3 for small r,
    where the difference cancels."""
    ratio = np.asarray(tau_s, dtype=float) / correlation_s
    safe = np.maximum(ratio, 1e-3)
    exact = 2.0 * variance / safe * (1.0 - (3.0 - 4.0 * np.exp(-safe) + np.exp(-2.0 * safe)) / (2.0 * safe))
    return np.where(ratio < 1e-3, 2.0 * variance * ratio / 3.0, exact)


def component_sigma(bias_instability: float) -> float:
    """Each process's standard deviation so that their sum's Allan deviation averages 0.664·B over the floor
    (geometric mean over log-spaced τ in 1…1000 s)."""
    unit = sum(gauss_markov_avar(_FLOOR_TAUS_S, 1.0, t) for t in CORRELATION_TIMES_S)
    floor = float(np.exp(np.mean(np.log(np.sqrt(unit)))))
    return FLICKER_FLOOR * bias_instability / floor


class BiasWander:
    """The wandering part of one gyroscope's bias, per axis, in the unit of `bias_instability`."""

    def __init__(self, bias_instability: float, rng: np.random.Generator, axes: int = 3) -> None:
        self.sigma = component_sigma(bias_instability) if bias_instability > 0 else 0.0
        self._rng = rng
        self._state = np.zeros((len(CORRELATION_TIMES_S), axes))
        self._t_s: float | None = None

    def at(self, t_s: np.ndarray) -> np.ndarray:
        """The wander (n, axes) at each of these increasing instants (none earlier than the last asked)."""
        t_s = np.atleast_1d(np.asarray(t_s, dtype=float))
        out = np.zeros((len(t_s), self._state.shape[1]))
        if self.sigma == 0.0:
            return out
        if self._t_s is None:  # the stationary distribution at the first instant
            self._state = self._rng.normal(0.0, self.sigma, self._state.shape)
            self._t_s = float(t_s[0])
        dt_s = np.maximum(np.diff(np.concatenate([[self._t_s], t_s])), 0.0)
        if len(t_s) > 2 and np.all(dt_s > 0) and np.allclose(dt_s[2:], dt_s[1], rtol=1e-9, atol=0.0):
            return self._at_one_rate(dt_s[0], dt_s[1], float(t_s[-1]), out)
        for i, (t, dt) in enumerate(zip(t_s, dt_s)):
            if dt > 0:
                self._step(dt)
                self._t_s = float(t)
            out[i] = self._state.sum(axis=0)
        return out

    def _step(self, dt_s: float) -> None:
        decay = np.exp(-dt_s / CORRELATION_TIMES_S)[:, None]
        self._state = self._state * decay + self.sigma * np.sqrt(1.0 - decay**2) * self._rng.normal(0.0, 1.0,
                                                                                                   self._state.shape)

    def _at_one_rate(self, first_dt_s: float, dt_s: float, last_t_s: float, out: np.ndarray) -> np.ndarray:
        """Instants `first_dt_s` after the last one asked, then every `dt_s`: the first step as any, the rest as
        an AR(1) filter per process (x_k = a·x_(k−1) + s·√(1 − a²)·w_k)."""
        self._step(first_dt_s)
        n, shape = len(out), self._state.shape
        noise = self._rng.normal(0.0, 1.0, (n - 1, *shape))  # the draws the steps would have made, in order
        decay = np.exp(-dt_s / CORRELATION_TIMES_S)
        states = np.empty((n, *shape))
        states[0] = self._state
        for process, a in enumerate(decay):
            drive = self.sigma * np.sqrt(1.0 - a * a) * noise[:, process, :]
            states[1:, process, :], _ = lfilter([1.0], [1.0, -a], drive, axis=0, zi=a * states[0:1, process, :])
        self._state = states[-1].copy()
        self._t_s = last_t_s
        return states.sum(axis=1)
