"""What the engine hands the store after each step: plain data, no file handles."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class DutPoseRecord:
    """One DUT's measurement of one pose."""

    serial: str
    raw_codes: np.ndarray            # (n, 3) signed 20-bit codes
    mean_g: np.ndarray               # (3,)
    stderr_g: np.ndarray             # (3,) standard error of the mean
    temperature_c: tuple[float, float]  # DUT's own sensor, before and after the block
    gravity_reference_g: np.ndarray  # (3,) expected reading from the commanded angles and the mount
    temperature_in_band: bool        # within the soak band of the temperature the soak settled at
    truth: dict[str, np.ndarray] | None = None


@dataclass(frozen=True)
class PoseRecord:
    step_key: str
    setpoint_c: float
    pose_number: int
    commanded_angles_deg: np.ndarray
    measured_angles_deg: np.ndarray
    gravity_fixture: np.ndarray
    t_start_s: float
    t_end_s: float
    chamber_temperature_c: tuple[float, float]  # before and after the acquisition
    duts: list[DutPoseRecord] = field(default_factory=list)


@dataclass(frozen=True)
class SoakTrace:
    """Temperatures polled during one soak, and how it ended."""

    label: str
    setpoint_c: float
    outcome: str                      # "stable"; "timeout" or "fault" when the campaign aborted during it
    t_s: np.ndarray                   # (n,)
    chamber_c: np.ndarray             # (n,)
    dut_c: np.ndarray                 # (n, n_dut)
    t_reached_s: float                # chamber air within tolerance of the setpoint
    t_stable_s: float                 # NaN unless stable
    settled_dut_c: np.ndarray         # (n_dut,) mean over the final window


@dataclass(frozen=True)
class Event:
    t_s: float
    level: str                        # "info" | "warning" | "error"
    kind: str                         # "transition", "soak", "pose", "fault", ...
    message: str
