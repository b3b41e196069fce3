"""Calibration math on arrays: the sensor-frame error model of the paper (Eq. 1)."""
