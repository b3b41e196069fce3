"""The package's logger: the engine's events go to it, the command line gives it its handlers."""

from __future__ import annotations

import logging

LOGGER = logging.getLogger("accelcal_rig")
