"""Accelerometer poses built in tests (the VectorPoses of an `accel` channel in g), and their fit by the
accelerometer's channel model."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from accelcal_rig.config.acceptance import Acceptance
from accelcal_rig.fit.acceleration import ACCELERATION, MODEL
from accelcal_rig.fit.acceptance import Judgement, judge
from accelcal_rig.fit.channel_model import ChannelFit
from accelcal_rig.fit.options import FitOptions
from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
from accelcal_rig.fit.thermal import ThermalModel
from accelcal_rig.fit.vector_model import fit_vector
from accelcal_rig.store.read import VectorPoses


def accel_poses(serial: str, range_g: float, lsb_g: float, setpoint_c: np.ndarray, t_s: np.ndarray,
                temperature_c: np.ndarray, mean_g: np.ndarray, stderr_g: np.ndarray, reference_g: np.ndarray,
                accuracy_arcsec: float, truth_parameters: np.ndarray | None, verification: np.ndarray,
                gravity_g: float = 1.0, truth_gravity_g: np.ndarray | None = None, gravity_uncertainty_g: float = 0.0,
                approach: np.ndarray | None = None, rate_c_per_min: np.ndarray | None = None) -> VectorPoses:
    """An accelerometer's poses, in the order and units the tests write them."""
    return VectorPoses(serial, "accel", "g", range_g, lsb_g, setpoint_c, t_s, temperature_c, mean_g, stderr_g,
                       reference_g, accuracy_arcsec, truth_parameters, verification, np.arange(len(setpoint_c)),
                       magnitude=gravity_g, truth_reference=truth_gravity_g, magnitude_u=gravity_uncertainty_g,
                       approach=approach, rate_c_per_min=rate_c_per_min)


def fit_accelerometer(poses: VectorPoses, options: FitOptions) -> ChannelFit:
    """The accelerometer's channel model's fit of these poses."""
    return fit_vector(poses, options, ACCELERATION)


def judge_accelerometer(figures: dict, thermal: ThermalModel, mode: str, acceptance: Acceptance, partial: str = "",
                        parameter_u: ParameterUncertainty | None = None) -> Judgement:
    """The accelerometer's channel model's judgement of these figures (a calibration of `mode` whose thermal model
    is `thermal`) against `acceptance`'s `accel` limits."""
    fitted = ChannelFit("X", SimpleNamespace(mode=mode), figures, thermal, parameter_u)  # type: ignore[arg-type]
    return judge(MODEL, "accel", fitted, acceptance, partial)
