"""accelcal-rig: unattended thermal calibration campaigns for MEMS accelerometers."""

__version__ = "0.1.0"
