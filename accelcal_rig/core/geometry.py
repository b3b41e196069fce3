"""Directions spread evenly over the sphere: for pose schedules and for seeking a worst case over every
orientation."""

from __future__ import annotations

import numpy as np


def fibonacci_sphere(count: int) -> np.ndarray:
    """`count` directions spread evenly over the sphere (Fibonacci lattice, deterministic)."""
    index = np.arange(count) + 0.5
    z = 1.0 - 2.0 * index / count
    radius = np.sqrt(1.0 - z**2)
    azimuth = np.pi * (1.0 + np.sqrt(5.0)) * index
    return np.column_stack([radius * np.cos(azimuth), radius * np.sin(azimuth), z])
