"""Directions spread evenly over the sphere (pose schedules, seeking a worst case over every orientation),
and a DUT's mounting on the fixture."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def fixture_to_dut(mount_euler_deg: tuple[float, float, float]) -> np.ndarray:
    """Fixture frame → a DUT's frame: the inverse of its mounting (`mount_euler_deg`, extrinsic x-y-z)."""
    return Rotation.from_euler("xyz", mount_euler_deg, degrees=True).inv().as_matrix()


def fibonacci_sphere(count: int) -> np.ndarray:
    """`count` directions spread evenly over the sphere (Fibonacci lattice, deterministic)."""
    index = np.arange(count) + 0.5
    z = 1.0 - 2.0 * index / count
    radius = np.sqrt(1.0 - z**2)
    azimuth = np.pi * (1.0 + np.sqrt(5.0)) * index
    return np.column_stack([radius * np.cos(azimuth), radius * np.sin(azimuth), z])
