"""How much disk a campaign needs, known before it starts: a pose's journal record is encoded for real,
the rest follows from what the files hold per pose and per event."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from accelcal_rig.store.codec import encode_pose
from accelcal_rig.store.hdf5_file import TEXT_BYTES
from accelcal_rig.store.records import ChannelPoseRecord, DutPoseRecord, PoseRecord

#: `rig run` starts only with this many times the estimated need free.
START_MARGIN = 1.5
#: Bytes the journal keeps back for the records that stop a campaign on a full disk (at least).
MIN_RESERVE_BYTES = 256 * 1024
#: Events a pose brings (its transitions, its line, the odd warning), and what one costs in the journal
#: (JSON), the campaign file (fixed-length text columns) and the log (a line).
_EVENTS_PER_POSE = 6
_EVENT_JOURNAL_BYTES = 100
_EVENT_FILE_BYTES = 8 + sum(TEXT_BYTES[name] for name in ("wall_time", "level", "kind", "message"))
_EVENT_LOG_BYTES = 140
#: A campaign file's fixed part (configs, plan, groups, checksums) and a journal's (its header).
_FILE_FIXED_BYTES = 256 * 1024
_JOURNAL_FIXED_BYTES = 64 * 1024
#: A calibration file: its fixed part, and per DUT.
_CALIBRATION_BYTES = (32 * 1024, 24 * 1024)


#: What a DUT measures, for the estimate: each channel's name and number of axes (an ADXL355: accel, 3).
DutChannels = Sequence[tuple[str, int]]
ACCELEROMETER: DutChannels = (("accel", 3),)


def pose_record_bytes(n_duts: int, samples_per_pose: int, n_axes: int, with_truth: bool,
                      dut_channels: Sequence[DutChannels] | None = None) -> int:
    """The journal bytes of one pose, encoded as the writer encodes it (`dut_channels`: each DUT's channels;
    by default every DUT an accelerometer)."""
    truth = {"parameters": np.zeros(12), "gravity_g": np.zeros(3), "temperature_c": np.asarray(0.0)}
    channels = dut_channels if dut_channels is not None else [ACCELEROMETER] * n_duts
    if any(len(dut) > 1 for dut in channels):  # a dry run may keep a gyroscope's wander beside it: bound it
        truth["gyro_wander_dps"] = np.zeros(3)
    duts = [DutPoseRecord(f"DUT-{k:04d}", {name: ChannelPoseRecord(np.zeros((samples_per_pose, axes), dtype="i4"),
                                                                   np.zeros(axes), np.zeros(axes), np.zeros(axes))
                                           for name, axes in channels[k]},
                          (0.0, 0.0), True, truth if with_truth else None)
            for k in range(n_duts)]
    pose = PoseRecord("T-100/pose0001", -100.0, 1, np.zeros(n_axes), np.zeros(n_axes), np.zeros(3), 0.0, 0.0,
                      (0.0, 0.0), duts)
    return len(encode_pose(pose))


def reserve_bytes(pose_bytes: int) -> int:
    """What the journal keeps back: the records of a stop, several times over a pose."""
    return max(MIN_RESERVE_BYTES, 4 * pose_bytes)


@dataclass(frozen=True)
class StorageEstimate:
    poses: int
    pose_bytes: int        # one pose in the journal
    journal_bytes: int
    file_bytes: int        # the campaign file (HDF5) when complete
    other_bytes: int       # log, calibration, the journal's reserve
    calibration_bytes: int

    @property
    def need_bytes(self) -> int:
        """Peak use: the journal, the campaign file twice (the old and the new version while it is
        replaced), the log, the calibration and the reserve."""
        return self.journal_bytes + 2 * self.file_bytes + self.other_bytes

    def remaining_bytes(self, poses_left: int) -> int:
        """What the rest of a campaign with `poses_left` poses to go still needs beyond what is stored: its
        journal records and log lines, a new campaign file beside the old, the calibration."""
        per_pose = self.pose_bytes + _EVENTS_PER_POSE * (_EVENT_JOURNAL_BYTES + _EVENT_LOG_BYTES)
        return poses_left * per_pose + self.file_bytes + self.calibration_bytes


def estimate_storage(poses: int, n_duts: int, samples_per_pose: int, n_axes: int, with_truth: bool,
                     dut_channels: Sequence[DutChannels] | None = None) -> StorageEstimate:
    pose_bytes = pose_record_bytes(n_duts, samples_per_pose, n_axes, with_truth, dut_channels)
    events = poses * _EVENTS_PER_POSE
    journal = _JOURNAL_FIXED_BYTES + poses * pose_bytes + events * _EVENT_JOURNAL_BYTES
    file = _FILE_FIXED_BYTES + int(1.05 * poses * pose_bytes) + events * _EVENT_FILE_BYTES
    calibration = _CALIBRATION_BYTES[0] + n_duts * _CALIBRATION_BYTES[1]
    other = events * _EVENT_LOG_BYTES + calibration + reserve_bytes(pose_bytes)
    return StorageEstimate(poses, pose_bytes, journal, file, other, calibration)


def megabytes(n_bytes: int) -> str:
    return f"{n_bytes / 1e6:.1f} MB"
