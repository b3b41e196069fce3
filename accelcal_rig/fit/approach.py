"""From which side each pose's temperature was approached: what a hysteretic sensor remembers.

Read off the DUT's own temperature history (its soak traces and its poses, in time order): the sign of the
change over the `LOOKBACK_S` before each pose, where it changed by more than `MOVED_C`; where it did not,
the direction it last moved in.
"""

from __future__ import annotations

import numpy as np

#: How far back a pose's temperature is compared.
LOOKBACK_S = 600.0
#: A change smaller than this is no direction (the reading's noise and its 0.11 °C steps).
MOVED_C = 0.3
#: A pose's rate of change is the slope of its DUT's readings this far either side of it.
RATE_HALF_WINDOW_S = 150.0
#: The spans of travel over which a hysteresis may swing from one branch to the other that the joint fit tries
#: beside the sign of the last change (a swing at once): it keeps the one its poses fit best.
HYSTERESIS_SPANS_C = (2.5, 5.0, 10.0, 20.0, 40.0)
#: The time constants, h, over which a hysteresis may relax towards the middle at rest (a package's stress
#: creeping), tried with each span; None: it holds its state. A ramp's checks are where it soaks, the ends, where
#: a relaxed state and a held one differ most.
HYSTERESIS_RELAXATIONS_H = (None, 1.0, 2.0, 4.0, 8.0)
#: Every (span, relaxation) pair the joint fit tries beside the sign of the last change, in the order
#: `hysteresis_states` gives them.
HYSTERESIS_CANDIDATES = tuple((span, relax) for span in HYSTERESIS_SPANS_C for relax in HYSTERESIS_RELAXATIONS_H)
#: The readings are averaged this far either side before the swing is followed (their noise and 0.11 °C steps
#: would otherwise walk it at rest).
STATE_HALF_WINDOW_S = 60.0


def temperature_rates_c_per_min(t_s: np.ndarray, temperature_c: np.ndarray, history_t_s: np.ndarray,
                                history_c: np.ndarray) -> np.ndarray:
    """Each pose's rate of temperature change, °C/min: the slope of a straight line through the DUT's
    readings within RATE_HALF_WINDOW_S either side of it (its soak polls and poses; centred, so it does not
    lag the rate where it changes, at a turn or a soak's start)."""
    times, readings = _history(t_s, temperature_c, history_t_s, history_c)
    start = np.searchsorted(times, t_s - RATE_HALF_WINDOW_S, side="left")
    stop = np.searchsorted(times, t_s + RATE_HALF_WINDOW_S, side="right")
    sums = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones_like(times), times, readings,
                                                            times * times, times * readings)]
    n, st, sy, stt, sty = (c[stop] - c[start] for c in sums)
    spread = n * stt - st * st
    slope = np.where(spread > 0, (n * sty - st * sy) / np.where(spread > 0, spread, 1.0), 0.0)
    return 60.0 * slope


def _history(t_s: np.ndarray, temperature_c: np.ndarray, history_t_s: np.ndarray,
             history_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    times = np.concatenate([history_t_s, t_s])
    readings = np.concatenate([history_c, temperature_c])
    order = np.argsort(times, kind="stable")
    return times[order], readings[order]


def approach_directions(t_s: np.ndarray, temperature_c: np.ndarray, history_t_s: np.ndarray,
                        history_c: np.ndarray) -> np.ndarray:
    """+1 (warming) or −1 (cooling) for each pose at `t_s` with `temperature_c`, from the history of
    readings (`history_*`, any order; the poses' own readings are added)."""
    times, readings = _history(t_s, temperature_c, history_t_s, history_c)
    before = np.interp(t_s - LOOKBACK_S, times, readings)
    change = temperature_c - before
    directions = np.zeros(len(t_s))
    last = 0.0
    for k in np.argsort(t_s, kind="stable"):  # carried forward in time where it did not move
        if abs(change[k]) > MOVED_C:
            last = float(np.sign(change[k]))
        directions[k] = last
    first = directions[np.argsort(t_s, kind="stable")]
    started = first[first != 0]
    directions[directions == 0] = started[0] if len(started) else 1.0  # before it first moved: as it then did
    return directions


def hysteresis_states(t_s: np.ndarray, temperature_c: np.ndarray, history_t_s: np.ndarray, history_c: np.ndarray,
                      candidates: tuple[tuple[float, float | None], ...] = HYSTERESIS_CANDIDATES) -> np.ndarray:
    """(S, N) each pose's hysteresis state in −1…+1 for each (span, relaxation) of `candidates`: a stop operator
    on the DUT's own temperature history (its readings, averaged within STATE_HALF_WINDOW_S either side), moving
    by 2 × the temperature's change / span and held at ±1 (+1 after warming through the whole span, −1 after
    cooling), relaxing towards 0 with its time constant (hours; None: not at all) as time passes.
    A sign of the last change (`approach_directions`) is the limit of a span of zero; a real sensor's package
    and die attach change state over some travel, so after a turn it passes through the middle, and their
    stress creeps back at rest."""
    times, readings = _history(t_s, temperature_c, history_t_s, history_c)
    start = np.searchsorted(times, times - STATE_HALF_WINDOW_S, side="left")
    stop = np.searchsorted(times, times + STATE_HALF_WINDOW_S, side="right")
    sums = np.concatenate([[0.0], np.cumsum(readings)])
    smooth = (sums[stop] - sums[start]) / (stop - start)
    change = np.diff(smooth, prepend=smooth[:1])
    elapsed_s = np.diff(times, prepend=times[:1])
    states = np.empty((len(candidates), len(times)))
    moved = np.flatnonzero(np.abs(smooth - smooth[0]) > MOVED_C) if len(smooth) else np.zeros(0, int)
    first = float(np.sign(smooth[moved[0]] - smooth[0])) if len(moved) else 1.0
    for k, (span, relax_h) in enumerate(candidates):
        kept = np.ones_like(elapsed_s) if relax_h is None else np.exp(-elapsed_s / (3600.0 * relax_h))
        state = first  # before it first moved: as it then did
        for i, (step, keep) in enumerate(zip(change.tolist(), kept.tolist())):
            state = min(1.0, max(-1.0, state * keep + 2.0 * step / span))
            states[k, i] = state
    return np.array([np.interp(t_s, times, row) for row in states]).reshape(len(candidates), len(t_s))
