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
class ChannelInfo:
    """One channel of one DUT as the campaign records it: what it measures, in what unit, on which axes, at
    which range and code size (the part's channel at the procedure's range)."""

    name: str                        # "accel", "gyro"
    quantity: str                    # "acceleration", "angular rate"
    unit: str                        # "g", "dps"
    axes: tuple[str, ...]
    range: float                     # ± full scale in `unit`
    lsb: float                       # `unit` per code

    def lsb_at(self, range_: Any) -> Any:
        """The code size at another range of the part (scalar or array): the part's codes are one width at every
        range, so it scales with the range."""
        return self.lsb * range_ / self.range

    def attrs(self) -> dict[str, Any]:
        return {"quantity": self.quantity, "unit": self.unit, "axes": list(self.axes), "range": self.range,
                "lsb": self.lsb}

    @classmethod
    def from_attrs(cls, name: str, attrs: dict[str, Any]) -> ChannelInfo:
        """From what `attrs()` wrote; ValueError when anything is of another kind."""
        axes = attrs["axes"]
        if not (isinstance(name, str) and name.isidentifier() and isinstance(axes, list) and 0 < len(axes) <= 16
                and all(isinstance(a, str) for a in axes)):
            raise ValueError(f"channel {name!r}: name or axes of another kind")
        return cls(name, str(attrs["quantity"]), str(attrs["unit"]), tuple(axes), float(attrs["range"]),
                   float(attrs["lsb"]))


def acceleration_channel(dut: dict[str, Any]) -> ChannelInfo:
    """The one channel of a campaign recorded before parts declared channels (formats 1 and 2): acceleration
    in g on x, y, z at the DUT's `range_g` and `lsb_g`."""
    return ChannelInfo("accel", "acceleration", "g", ("x", "y", "z"), float(dut["range_g"]), float(dut["lsb_g"]))


@dataclass(frozen=True)
class ChannelPoseRecord:
    """One channel of one DUT at one pose."""

    raw_codes: np.ndarray            # (n, axes) signed codes
    mean: np.ndarray                 # (axes,) in the channel's unit (codes × lsb)
    stderr: np.ndarray               # (axes,) standard error of the mean
    reference: np.ndarray            # (axes,) what the channel should read in the DUT frame: gravity from the
                                     # commanded angles and the mount; the table's rate (zero at rest)
    range: float | None = None       # ± full scale of this record when not the campaign's (a gyroscope's finer
                                     # range at rest: engine/step_ranges.py); None: the channel's (ChannelInfo)


@dataclass(frozen=True)
class DutPoseRecord:
    """One DUT's measurement of one pose: each of its channels, and its own temperature sensor."""

    serial: str
    channels: dict[str, ChannelPoseRecord]
    temperature_c: tuple[float, float]  # DUT's own sensor, before and after the block
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
    #: The ramp before it: the chamber air polled from the set point's write (its first row) until it was
    #: reached (empty: no ramp was run for it in this run, or a file from before ramps were kept). What
    #: `rig characterise` fits the chamber's rates and lag to.
    ramp_t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ramp_chamber_c: np.ndarray = field(default_factory=lambda: np.zeros(0))


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


#: The plan kinds of steps that store a pose: a calibration pose, a verification pose, a rate step (a gyroscope's
#: calibration) and its verification, a block of a still noise record.
MEASUREMENT_KINDS = ("pose", "verify", "rate", "verify-rate", "noise")
#: The kinds whose samples are taken at rest, the table standing at the pose (an accelerometer's poses).
STATIC_KINDS = ("pose", "verify")
#: The kinds never fitted: every figure of how good a calibration is comes from them.
VERIFICATION_KINDS = ("verify", "verify-rate")


@dataclass(frozen=True)
class StoredPlan:
    """The compiled plan as the campaign keeps it: one row per step."""

    step_key: tuple[str, ...]
    kind: tuple[str, ...]             # "soak" | MEASUREMENT_KINDS ("verify", "verify-rate": never fitted)
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
        return frozenset(k for k, kind in zip(self.step_key, self.kind) if kind in VERIFICATION_KINDS)

    def keys_of(self, *kinds: str) -> frozenset[str]:
        """The keys of the steps of these kinds."""
        return frozenset(k for k, kind in zip(self.step_key, self.kind) if kind in kinds)


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
    duts: list[dict[str, Any]]        # per DUT: serial, name, mount_euler_deg, range_g, odr_hz, lsb_g, driver, endpoint,
                                      # customer, received_date, condition (the last three "" when not stated)
    instruments: dict[str, dict[str, str]]  # chamber, turntable: driver, endpoint, make, model, serial
    turntable_accuracy_arcsec: float
    #: Dry runs: each simulated DUT's hidden model (attributes and `polynomial_coefficients`).
    truth: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: Each DUT's channels by serial (absent: formats 1 and 2, whose DUTs measured acceleration only).
    channels: dict[str, tuple[ChannelInfo, ...]] = field(default_factory=dict)
    #: The references the rig config named when the campaign was created, by key (`turntable_angle`, …): each
    #: its certificate, issuer, due_date (ISO), make, model and serial; {} for one the rig config did not state.
    #: Absent before campaigns recorded them.
    references: dict[str, dict[str, str]] = field(default_factory=dict)

    @property
    def serials(self) -> list[str]:
        return [str(d["serial"]) for d in self.duts]

    def dut_channels(self, serial: str) -> tuple[ChannelInfo, ...]:
        """What the DUT `serial` measures, in its part's order."""
        if serial in self.channels:
            return self.channels[serial]
        return (acceleration_channel(self.duts[self.serials.index(serial)]),)


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
