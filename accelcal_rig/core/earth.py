"""The Earth's rotation as a rate table's gyroscopes see it: a rate of 15.04 °/h about the Earth's axis, in
the lab's world frame (z up, x the table's x axis at zero angles) from the site's latitude and the table's
heading."""

from __future__ import annotations

import numpy as np

#: The Earth's sidereal rotation rate (IERS: 7.292115 × 10⁻⁵ rad/s), in °/s.
EARTH_RATE_DPS = float(np.degrees(7.292115e-5))


def earth_rate_world_dps(latitude_deg: float, heading_deg: float | None) -> np.ndarray:
    """The Earth's rate in the world frame, °/s: its vertical component sin(latitude)·Ω always; its horizontal
    one, cos(latitude)·Ω towards true north, only with the heading (the azimuth of world x east of north),
    zero without (what the rig cannot place it leaves out)."""
    latitude = np.radians(latitude_deg)
    vertical = EARTH_RATE_DPS * np.sin(latitude)
    if heading_deg is None:
        return np.array([0.0, 0.0, vertical])
    heading = np.radians(heading_deg)
    # World x points at azimuth ψ, world y (z up, right-handed) at ψ − 90°: north is (cos ψ, sin ψ) in them.
    horizontal = EARTH_RATE_DPS * np.cos(latitude)
    return np.array([horizontal * np.cos(heading), horizontal * np.sin(heading), vertical])
