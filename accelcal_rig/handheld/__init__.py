"""Calibration without a turntable: a continuous recording of a sensor placed by hand in many orientations."""
