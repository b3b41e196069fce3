"""The static-interval detector on synthetic hand-held recordings whose still periods are known."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.errors import ConfigError
from accelcal_rig.handheld.static_intervals import DetectorSettings, detect_static_intervals
from accelcal_rig.sim.handheld import handheld_recording


@pytest.mark.parametrize("rate_hz", [100.0, 125.0, 1000.0])
def test_every_still_period_is_found_and_no_moving_sample_is_in_one(rate_hz: float) -> None:
    recording = handheld_recording("HH-1", 15, rate_hz, np.random.default_rng(1))
    detection = detect_static_intervals(recording.t_s, recording.raw_g, recording.temperature_c, DetectorSettings())
    assert len(detection.intervals) == recording.orientations
    for interval in detection.intervals:
        inside = (recording.t_s >= interval.start_s) & (recording.t_s <= interval.end_s)
        assert recording.still[inside].all()
        assert inside.sum() == interval.n_samples
        assert interval.temperature_c == pytest.approx(25.0, abs=0.02)
    found = sum(i.n_samples for i in detection.intervals)
    assert found > 0.8 * recording.still.sum()  # most of each still period is used


def test_a_recording_that_starts_moving_is_refused() -> None:
    recording = handheld_recording("HH-1", 10, 100.0, np.random.default_rng(2), initial_still_s=0.2)
    with pytest.raises(ConfigError, match="the first 2 s are not still"):
        detect_static_intervals(recording.t_s, recording.raw_g, None, DetectorSettings(), "walk.csv")


def test_gaps_in_time_split_the_recording() -> None:
    rng = np.random.default_rng(3)
    t = np.concatenate([np.arange(300) / 100.0, 10.0 + np.arange(300) / 100.0])  # two still blocks, a gap
    accel = np.vstack([np.tile([0, 0, 1.0], (300, 1)), np.tile([1.0, 0, 0], (300, 1))]) + rng.normal(0, 2e-4, (600, 3))
    detection = detect_static_intervals(t, accel, None, DetectorSettings())
    assert [round(i.mean_g[0]) for i in detection.intervals] == [0, 1]
