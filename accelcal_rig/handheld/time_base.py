"""Whether a recording's time base can be what it says: the sampling rate its time column gives must lie within
the data rates a MEMS part runs at — the part's own (`--part`), else any known accelerometer's — with a margin for a
logger's clock and for a logger keeping every other sample. A sample-index column read as seconds gives 1 Hz
(9414 samples over 2.6 hours); one in milliseconds read as seconds, a thousandth of the rate: a fit of either
finds "static intervals" that span motion, so the recording is refused before it is fitted."""

from __future__ import annotations

import numpy as np

from accelcal_rig.errors import ConfigError
from accelcal_rig.parts.registry import known_parts

ACCELERATION = "acceleration"
#: How far below the slowest and above the fastest data rate a recording's rate may lie.
RATE_MARGIN = 2.0
#: What to check, by the unit the time column was read in.
_HINTS = {"s": "a column counting samples needs --time-unit samples --rate-hz N, one in milliseconds --time-unit ms",
          "ms": "a column in seconds needs --time-unit s, one counting samples --time-unit samples --rate-hz N",
          "samples": "check --rate-hz"}
_READ_AS = {"s": "seconds", "ms": "milliseconds", "samples": "samples"}


def plausible_rates_hz(part_name: str) -> tuple[float, float, str]:
    """(lowest, highest) sampling rate taken for a recording of the part, and whose data rates bound them."""
    parts = known_parts()
    if part_name in parts:
        rates, whose = parts[part_name].output_data_rates_hz, f"the {parts[part_name].label}'s data rates"
    else:  # a handheld recording is an accelerometer's (a magnetometer's slowest rates are no bound for it)
        rates = tuple(r for p in parts.values() if any(c.quantity == ACCELERATION for c in p.channels)
                      for r in p.output_data_rates_hz)
        whose = "any known accelerometer's data rates"
    return min(rates) / RATE_MARGIN, max(rates) * RATE_MARGIN, whose


def check_time_base(source: str, column: str, time_unit: str, t_s: np.ndarray, part_name: str) -> None:
    """Refuse, in one line naming the file and its time column, a recording whose sampling rate no MEMS part of
    its kind runs at."""
    rate_hz = 1.0 / float(np.median(np.diff(t_s)))
    low, high, whose = plausible_rates_hz(part_name)
    if low <= rate_hz <= high:
        return
    pace = "slower" if rate_hz < low else "faster"
    raise ConfigError(f"{source}: column {column}: {len(t_s)} samples at {rate_hz:.4g} Hz read as {_READ_AS[time_unit]}, "
                      f"{pace} than {whose} allow ({low:.4g} … {high:.4g} Hz): not a time base a recording has; "
                      f"{_HINTS[time_unit]}")
