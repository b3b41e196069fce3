"""accelcal-rig: unattended thermal calibration of MEMS accelerometers, gyroscopes and IMUs."""

# The one source of the version: pyproject.toml reads it (tool.setuptools.dynamic), `rig --version` prints it,
# CHANGELOG.md names it.
__version__ = "0.9.0"
