"""Find where a hand-held recording stands still (the imu_tk approach).

The variance of each axis over a sliding window, summed over the axes, is compared with a threshold set
from the recording's first seconds, when the sensor lies still: `threshold_factor` × their median. A run
of window centres below it (so every sample is at least half a window away from motion) at least
`min_interval_s` long is a static interval; its mean is one pose of a norm-only fit. A gap in time (a campaign file's moves, lost data)
splits the recording into segments that are searched separately.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from accelcal_rig.errors import ConfigError


@dataclass(frozen=True)
class DetectorSettings:
    window_s: float = 0.5
    init_s: float = 2.0
    threshold_factor: float = 10.0
    min_interval_s: float = 1.0


@dataclass(frozen=True)
class StaticInterval:
    start_s: float
    end_s: float
    n_samples: int
    mean_g: np.ndarray           # (3,)
    stderr_g: np.ndarray         # (3,) of the mean
    temperature_c: float         # NaN without a temperature channel


@dataclass(frozen=True)
class Detection:
    intervals: list[StaticInterval]
    threshold_g2: float          # on the summed windowed variance
    init_variance_g2: float      # median summed variance over the initial still period
    rate_hz: float
    window_samples: int


def _moving_variance(values: np.ndarray, width: int) -> np.ndarray:
    """Variance over a centred window of `width` samples for each sample whose window fits (NaN at the
    edges), per column, from cumulative sums."""
    n = len(values)
    out = np.full(values.shape, np.nan)
    if n < width:
        return out
    centred = values - values.mean(axis=0)
    s1 = np.vstack([np.zeros((1, values.shape[1])), np.cumsum(centred, axis=0)])
    s2 = np.vstack([np.zeros((1, values.shape[1])), np.cumsum(centred**2, axis=0)])
    total = s1[width:] - s1[:-width]
    squares = s2[width:] - s2[:-width]
    variance = np.maximum(squares / width - (total / width) ** 2, 0.0)
    half = width // 2
    out[half:half + len(variance)] = variance
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) index pairs of the runs of True."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def detect_static_intervals(t_s: np.ndarray, accel_g: np.ndarray, temperature_c: np.ndarray | None,
                            settings: DetectorSettings, source: str = "recording") -> Detection:
    t_s = np.asarray(t_s, dtype=float)
    accel_g = np.asarray(accel_g, dtype=float)
    steps = np.diff(t_s)
    rate_hz = 1.0 / float(np.median(steps))
    width = max(3, int(round(settings.window_s * rate_hz)))
    breaks = np.flatnonzero(steps > 2.5 / rate_hz) + 1
    segments = list(zip(np.r_[0, breaks], np.r_[breaks, len(t_s)]))
    variance = np.full(len(t_s), np.nan)
    for start, stop in segments:
        variance[start:stop] = _moving_variance(accel_g[start:stop], width).sum(axis=1)
    initial = (t_s < t_s[0] + settings.init_s) & np.isfinite(variance)
    if not initial.any():
        raise ConfigError(f"{source}: the initial still period ({settings.init_s:g} s) is shorter than one window "
                          f"({settings.window_s:g} s): lengthen --init-s or shorten --window-s")
    init_variance = float(np.median(variance[initial]))
    quiet = float(np.nanpercentile(variance, 5))
    if init_variance > 100.0 * max(quiet, 1e-30):
        raise ConfigError(f"{source}: the first {settings.init_s:g} s are not still (their variance is "
                          f"{init_variance / quiet:.0f}× the quietest stretches): start the recording with the sensor "
                          "at rest, or point --init-s at a still stretch's length")
    threshold = settings.threshold_factor * init_variance
    intervals = []
    for start, stop in _runs(np.nan_to_num(variance, nan=np.inf) < threshold):
        first, last = start, stop  # centres of quiet windows: each a half window away from any motion
        if last - first < 2 or t_s[last - 1] - t_s[first] < settings.min_interval_s:
            continue
        block = accel_g[first:last]
        n = last - first
        temperature = float(np.mean(temperature_c[first:last])) if temperature_c is not None else float("nan")
        intervals.append(StaticInterval(float(t_s[first]), float(t_s[last - 1]), n, block.mean(axis=0),
                                        block.std(axis=0, ddof=1) / np.sqrt(n), temperature))
    return Detection(intervals, threshold, init_variance, rate_hz, width)
