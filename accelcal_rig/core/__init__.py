"""Neutral ground: the clock, waiting on it, signal deferral, fixture thermal physics, formatting.

Nothing here imports any other part of the package (only `accelcal_rig.errors`), so every layer may use it.
"""
