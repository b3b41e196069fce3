"""How much disk a campaign needs, known before it starts: a pose's journal record is encoded for real,
the campaign file's size follows from the data it holds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from accelcal_rig.store.codec import encode_pose
from accelcal_rig.store.records import DutPoseRecord, PoseRecord

#: `rig run` starts only with this many times the estimated need free.
START_MARGIN = 1.5
#: Bytes the journal keeps back for the records that stop a campaign on a full disk (at least).
MIN_RESERVE_BYTES = 256 * 1024
#: A campaign file's fixed part (configs, plan, groups, checksums), and per stored event (journal and log).
_FILE_FIXED_BYTES = 256 * 1024
_EVENT_BYTES = 160
_EVENTS_PER_POSE = 4
_CALIBRATION_BYTES = 64 * 1024


def pose_record_bytes(n_duts: int, samples_per_pose: int, n_axes: int, with_truth: bool) -> int:
    """The journal bytes of one pose, encoded as the writer encodes it."""
    truth = {"parameters": np.zeros(12), "gravity_g": np.zeros(3), "temperature_c": np.float64(0.0)}
    duts = [DutPoseRecord(f"DUT-{k:04d}", np.zeros((samples_per_pose, 3), dtype="i4"), np.zeros(3), np.zeros(3),
                          (0.0, 0.0), np.zeros(3), True, truth if with_truth else None) for k in range(n_duts)]
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

    @property
    def need_bytes(self) -> int:
        """Peak use: the journal, the campaign file twice (the old and the new version while it is
        replaced), the log, the calibration and the reserve."""
        return self.journal_bytes + 2 * self.file_bytes + self.other_bytes

    def remaining_bytes(self, poses_left: int) -> int:
        """What the rest of a campaign with `poses_left` poses to go still needs beyond what is stored: its
        journal records, events and log lines, a new campaign file beside the old, the calibration."""
        return poses_left * (self.pose_bytes + 2 * _EVENTS_PER_POSE * _EVENT_BYTES) + self.file_bytes + \
            _CALIBRATION_BYTES


def estimate_storage(poses: int, n_duts: int, samples_per_pose: int, n_axes: int, with_truth: bool) -> StorageEstimate:
    pose_bytes = pose_record_bytes(n_duts, samples_per_pose, n_axes, with_truth)
    events_bytes = poses * _EVENTS_PER_POSE * _EVENT_BYTES
    journal = 64 * 1024 + poses * pose_bytes + events_bytes
    file = _FILE_FIXED_BYTES + int(1.05 * poses * pose_bytes) + events_bytes
    other = events_bytes + _CALIBRATION_BYTES + reserve_bytes(pose_bytes)
    return StorageEstimate(poses, pose_bytes, journal, file, other)


def megabytes(n_bytes: int) -> str:
    return f"{n_bytes / 1e6:.1f} MB"
