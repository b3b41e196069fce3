"""Shared by the benchmarks: the campaigns' own progress and warnings are not the figures."""

from __future__ import annotations

import logging

from accelcal_rig.core.logger import LOGGER


def silence_campaign_log() -> None:
    """Keep the engine's log off the console (and off the root logger) while a benchmark prints figures."""
    LOGGER.setLevel(logging.WARNING)
    LOGGER.propagate = False
    LOGGER.addHandler(logging.NullHandler())


def throwaway_registry() -> None:
    """The dry runs a benchmark starts record their calibrations in a registry of its own, not the user's."""
    import atexit
    import os
    import shutil
    import tempfile

    folder = tempfile.mkdtemp(prefix="accelcal-bench-registry-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    os.environ["ACCELCAL_REGISTRY"] = os.path.join(folder, "registry.sqlite")
    os.environ["ACCELCAL_DRY_RUN_REGISTRY"] = os.path.join(folder, "dry-runs.sqlite")
