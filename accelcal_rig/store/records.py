"""What the engine hands the store, and what the store keeps: plain data, no file handles."""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field
from typing import Any

import numpy as np


def plain_value(value: Any) -> Any:
    """JSON-able: numpy scalars and arrays become Python numbers and lists, bytes text."""
    if isinstance(value, dict):
        return {str(k): plain_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain_value(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, bytes):
        return value.decode(errors="replace")
    return value


def utc_now() -> str:
    """Wall-clock time as the campaign records it: ISO 8601, UTC, whole seconds."""
    return dt.datetime.now(dt.UTC).isoformat(timespec="seconds")


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
    serials: tuple[str, ...] = ()     # whose temperatures the columns of dut_c are (empty: the campaign's order)


@dataclass(frozen=True)
class Event:
    t_s: float
    level: str                        # "info" | "warning" | "error"
    kind: str                         # "transition", "soak", "pose", "fault", ...
    message: str


@dataclass(frozen=True)
class StoredEvent:
    """An event as the campaign keeps it: with the wall-clock time it was logged."""

    t_s: float
    wall_time: str
    level: str
    kind: str
    message: str


#: The plan kinds of steps that store a pose: a calibration pose, a verification pose.
MEASUREMENT_KINDS = ("pose", "verify")


@dataclass(frozen=True)
class StoredPlan:
    """The compiled plan as the campaign keeps it: one row per step."""

    step_key: tuple[str, ...]
    kind: tuple[str, ...]             # "soak" | "pose" | "verify" (a verification pose, never fitted)
    setpoint_c: np.ndarray            # (S,)
    pose_number: np.ndarray           # (S,) 1-based, 0 for soaks
    angles_deg: np.ndarray            # (S, A) commanded angles, NaN for soaks
    gravity_fixture: np.ndarray       # (S, 3) expected gravity in the fixture frame, NaN for soaks
    fingerprint: str
    axis_names: tuple[str, ...]

    @property
    def pose_keys(self) -> list[str]:
        """Every pose's key, calibration and verification."""
        return [k for k, kind in zip(self.step_key, self.kind) if kind in MEASUREMENT_KINDS]

    @property
    def verification_keys(self) -> frozenset[str]:
        return frozenset(k for k, kind in zip(self.step_key, self.kind) if kind == "verify")


@dataclass(frozen=True)
class CampaignHeader:
    """Everything known of a campaign when it is created, before its first pose."""

    campaign_id: str                  # random, so a file and its journal can be matched
    created: str                      # wall-clock time (ISO 8601 UTC)
    software_version: str
    attrs: dict[str, Any]             # procedure_name, procedure_path, rig_name, rig_path, dry_run, seed, clock,
                                      # samples_per_pose, fit_mode, …: the file's root attributes
    procedure_yaml: str
    rig_yaml: str
    plan: StoredPlan
    duts: list[dict[str, Any]]        # per DUT: serial, name, mount_euler_deg, range_g, odr_hz, lsb_g, driver, endpoint
    instruments: dict[str, dict[str, str]]
    turntable_accuracy_arcsec: float
    #: Dry runs: each simulated DUT's hidden model (attributes and `polynomial_coefficients`).
    truth: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def serials(self) -> list[str]:
        return [str(d["serial"]) for d in self.duts]


@dataclass(frozen=True)
class RunStart:
    """One run of the campaign (1 created it; each resume adds one)."""

    run: int
    pid: int
    host: str
    started: str                      # wall-clock time


@dataclass(frozen=True)
class StateChange:
    state: str                        # "running" | "done" | "aborted"
    reason: str                       # why it aborted, empty otherwise
    wall_time: str
