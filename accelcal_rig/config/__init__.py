"""Procedure (what to do) and rig config (what the rig is): YAML files validated before anything moves."""

from accelcal_rig.config.load import LoadedConfig, load_procedure, load_rig, resolve_rig_path
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig

__all__ = ["LoadedConfig", "Procedure", "RigConfig", "load_procedure", "load_rig", "resolve_rig_path"]
