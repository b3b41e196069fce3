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
