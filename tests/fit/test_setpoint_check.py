"""The early check's figures on synthetic DUTs at the paper's 24 poses: a sound DUT near 1× its noise, its
mount within a degree and every axis near 1 g/g; a loose one, one turned on its mount and one with a dead
axis each found by its own figure and only by it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from accelcal_rig.fit.early_check import DROPPED, CheckLimits, Finding, dropped, findings, logged_findings, parse
from accelcal_rig.fit.setpoint_check import design_determined, setpoint_figures
from accelcal_rig.fit.sfem import IDENTITY_PARAMETERS, distort
from accelcal_rig.plan.schedules import paper_24, six_position
from accelcal_rig.store.records import StoredEvent

NOISE_G = 12e-6          # a 200-sample mean of an ADXL355 at 125 Hz
LIMITS = CheckLimits(residual_ratio=20.0, direction_deg=10.0, axis_gain=0.5)
PARAMETERS = IDENTITY_PARAMETERS + np.array([0.02, -0.01, 0.015, 0.008, -0.006, 0.004, 0.003, -0.004, 0.002,
                                             0.005, -0.007, 0.004])


def readings(rng: np.random.Generator, expected_g: np.ndarray, turn: np.ndarray | None = None,
             loose_deg: float = 0.0, dead_axis: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(means, standard errors) of one DUT whose true specific force is the expected one turned by `turn`,
    and at each pose by a random `loose_deg` (RMS); its `dead_axis` reads its bias."""
    true_g = expected_g if turn is None else expected_g @ turn.T
    if loose_deg:
        wobble = Rotation.from_rotvec(rng.normal(0, np.radians(loose_deg) / np.sqrt(3), (len(true_g), 3)))
        true_g = wobble.apply(true_g)
    mean_g = distort(true_g, PARAMETERS)
    if dead_axis is not None:
        mean_g[:, dead_axis] = PARAMETERS[dead_axis]
    return mean_g + rng.normal(0, NOISE_G, mean_g.shape), np.full(mean_g.shape, NOISE_G)


def fixture_figures(seed: int = 0):
    rng = np.random.default_rng(seed)
    expected = paper_24()
    duts = [readings(rng, expected), readings(rng, expected, loose_deg=3.0),
            readings(rng, expected, Rotation.from_euler("z", 180, degrees=True).as_matrix()),
            readings(rng, expected, Rotation.from_euler("x", 90, degrees=True).as_matrix()),
            readings(rng, expected, dead_axis=1)]
    mean, stderr = np.array([d[0] for d in duts]), np.array([d[1] for d in duts])
    return setpoint_figures(mean, stderr, np.broadcast_to(expected, mean.shape), np.radians(3 / 3600), 0.5)


def test_each_fault_is_found_by_its_own_figure_and_a_sound_dut_by_none() -> None:
    figures = fixture_figures()
    ratio, direction, gain = figures.residual_ratio, figures.direction_deg, figures.axis_gain
    assert 0.5 < ratio[0] < 2 and direction[0] < 1.0 and np.all(np.abs(gain[0] - 1) < 0.02)
    assert ratio[1] > 500 and direction[1] < 3.0               # loose: residuals, not the direction
    assert ratio[2] < 2 and direction[2] == pytest.approx(180, abs=1)   # turned: the direction, not the residuals
    assert ratio[3] < 2 and direction[3] == pytest.approx(90, abs=1)
    assert np.all(np.abs(gain[2:4] - 1) < 0.02)                # a turned DUT's axes all respond
    assert gain[4, 1] < 0.01 and np.all(gain[4, [0, 2]] > 0.98) and np.isnan(direction[4])


def test_findings_name_each_dut_once_for_what_it_has() -> None:
    found = findings(["A", "B", "C", "D", "E"], 25.0, fixture_figures(1), LIMITS, "warn")
    assert [(f.serial, f.finding, f.axis) for f in found] == [
        ("B", "loose_mount", ""), ("C", "misoriented", ""), ("D", "misoriented", ""), ("E", "dead_axis", "y")]


def test_a_finding_reads_as_a_person_says_it_and_parses_back() -> None:
    finding = Finding("SN123", 25.0, "loose_mount", 41.23, 20.0, "warn")
    assert finding.message() == "DUT SN123 at +25 °C: residuals 41.2× its noise (limit 20×): loose mount?"
    dead = Finding("SN9", -40.0, "dead_axis", 0.0001, 0.5, "drop", "z")
    assert dead.message().endswith("axis z responds 0.000 g/g (limit 0.5 g/g): dead axis?" + DROPPED)
    turned = Finding("SN7", 60.0, "misoriented", 179.96, 10.0, "warn")
    for original in (finding, dead, turned):
        back = parse(original.message())
        assert back is not None and (back.serial, back.setpoint_c, back.finding, back.action, back.axis) == (
            original.serial, original.setpoint_c, original.finding, original.action, original.axis)
        assert back.value == pytest.approx(original.value, abs=0.06) and back.limit == original.limit
    assert parse("early check at +25 °C: residuals 0.9…1.1× their noise") is None


def test_dropped_duts_are_read_from_the_event_log_once_each() -> None:
    log = [StoredEvent(1.0, "", "warning", "early_check", Finding("A", 25.0, "loose_mount", 99, 20, "drop").message()),
           StoredEvent(2.0, "", "warning", "early_check", Finding("A", 25.0, "dead_axis", 0, 0.5, "drop", "x").message()),
           StoredEvent(3.0, "", "warning", "early_check", Finding("B", 25.0, "misoriented", 90, 10, "warn").message()),
           StoredEvent(4.0, "", "warning", "pose", Finding("C", 25.0, "misoriented", 90, 10, "drop").message())]
    assert [f.serial for f in logged_findings(log)] == ["A", "A", "B"]
    assert dropped(log) == {"A": "dropped by the early check: DUT A at +25 °C: residuals 99.0× its noise (limit "
                                 "20×): loose mount?"}


def test_poses_near_one_plane_leave_the_check_undetermined() -> None:
    assert design_determined(paper_24()) and design_determined(six_position())
    level = np.array([[np.sin(a), 0.0, np.cos(a)] for a in np.radians([-10, -5, 0, 5, 10])])
    assert not design_determined(level)
    assert not design_determined(six_position()[:4])  # 12 equations for 12 parameters: nothing left to judge
