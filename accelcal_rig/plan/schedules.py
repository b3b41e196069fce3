"""Pose schedules as gravity directions in the fixture frame (what a perfect DUT would read, in g)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.core.geometry import fibonacci_sphere

_STEPS_DEG = np.arange(8) * 45.0


def _circle(axis: str, start: np.ndarray) -> np.ndarray:
    """The DUT turned in eight 45° steps about its `axis`: gravity in its frame turns the other way."""
    return Rotation.from_euler(axis, _STEPS_DEG[:, None], degrees=True).inv().apply(start)


def paper_24() -> np.ndarray:
    """Table 1 of the paper, in its row order.

    Rows 1–8 keep z fixed with y starting vertical (steps about z); rows 9–16 keep y fixed with z
    starting vertical (steps about y); rows 17–24 keep x fixed with z starting vertical (steps about x).
    """
    x_hat, y_hat, z_hat = np.eye(3)
    return np.vstack([_circle("z", y_hat), _circle("y", z_hat), _circle("x", z_hat)])


def six_position() -> np.ndarray:
    """+x, −x, +y, −y, +z, −z up."""
    return np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)


def tilt(pitch_roll_deg: np.ndarray) -> np.ndarray:
    """The reading (+1 g up) at each pitch φ and roll θ: Eq. 10 inverted on gravity g = −reading,
    g = (cos φ sin θ, −sin φ, −cos φ cos θ)."""
    pitch, roll = np.radians(np.asarray(pitch_roll_deg, dtype=float)).T
    return np.column_stack([-np.cos(pitch) * np.sin(roll), np.sin(pitch), np.cos(pitch) * np.cos(roll)])


def sphere(count: int) -> np.ndarray:
    """`count` directions spread evenly over the sphere (Fibonacci lattice, deterministic)."""
    return fibonacci_sphere(count)
