"""The early check in a dry run: a loose DUT and one mounted turned are flagged at the first setpoint (the
event log, the notification, `rig status`), the sound ones at no setpoint; `action: drop` leaves the
flagged DUT out of the fit with its reason, its poses kept in the file."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.assembly import run_campaign
from accelcal_rig.cli.campaign import campaign_status
from accelcal_rig.cli.status_text import status_lines
from accelcal_rig.engine.notify import Notification
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.calibration import load_calibration
from accelcal_rig.plan.compile import compile_plan
from accelcal_rig.plan.steps import CheckSetpoint, MeasurePose, VerifyPose
from accelcal_rig.store.read import load_campaign
from tests.engine.test_campaign import events

LOOSE, TURNED, SOUND = "ADX355-A002", "ADX355-A003", ("ADX355-A001", "ADX355-A004")
FAULTS = f"sensor_loose={LOOSE},sensor_misoriented={TURNED}"
#: Two soaked setpoints of six positions, a few samples a pose: the shortest campaign the check judges twice.
PROCEDURE = """\
name: early
rig: sim.yaml
setpoints_c: [30, 40]
soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}
schedule: {kind: six-position}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
"""


def run(write, workdir: Path, extra: str = "", faults: str | None = FAULTS) -> Path:
    output = workdir / "early.h5"
    run_campaign(prepare(write("early.yaml", PROCEDURE + extra), faults=faults), output, dry_run=True, seed=1,
                 overwrite=True, calibration=output.with_suffix(".calibration.yaml"))
    return output


def flagged(output: Path) -> list[tuple[str, float, str]]:
    return [(f["serial"], f["setpoint_c"], f["finding"]) for f in campaign_status(output, None)["early_check"]]


def test_the_check_runs_after_the_calibration_poses_and_before_the_verification_poses(write) -> None:
    prepared = prepare(write("early.yaml", PROCEDURE + "verify: {schedule: {kind: sphere, count: 7}}\n"))
    body = compile_plan(prepared.procedure.model, prepared.rig.model).stages[0].body
    kinds = [type(step) for step in body]
    assert kinds == [MeasurePose] * 6 + [CheckSetpoint] + [VerifyPose] * 7
    none = prepare(write("none.yaml", PROCEDURE + "early_check: {action: none}\n"))
    assert not any(isinstance(s, CheckSetpoint) for s in compile_plan(none.procedure.model, none.rig.model).steps)


def test_a_loose_and_a_turned_dut_are_flagged_at_the_first_setpoint_and_the_sound_ones_never(write,
                                                                                              workdir: Path) -> None:
    output = run(write, workdir)
    assert flagged(output) == [(LOOSE, 30.0, "loose_mount"), (TURNED, 30.0, "misoriented"),
                               (LOOSE, 40.0, "loose_mount"), (TURNED, 40.0, "misoriented")]
    warnings = [m for m in events(output, "early_check") if m.startswith("DUT ")]
    assert warnings[0].startswith(f"DUT {LOOSE} at +30 °C: residuals ") and warnings[0].endswith(
        "× its noise (limit 20×): loose mount?")
    assert warnings[1].startswith(f"DUT {TURNED} at +30 °C: gravity 179.") and "(limit 10°)" in warnings[1]
    summaries = [m for m in events(output, "early_check") if m.startswith("early check at")]
    assert len(summaries) == 2 and all(m.endswith("2 of 4 DUTs flagged") for m in summaries)
    status = campaign_status(output, None)
    assert {f["action"] for f in status["early_check"]} == {"warn"}
    assert sum(line.startswith("flagged    ") for line in status_lines(status)) == 4
    assert set(load_calibration(output.with_suffix(".calibration.yaml")).of_quantity("acceleration")) == {LOOSE, TURNED, *SOUND}


def test_no_dut_of_a_sound_fixture_is_flagged(write, workdir: Path) -> None:
    assert flagged(run(write, workdir, faults=None)) == []


def test_a_dead_axis_is_flagged_by_its_name(write, workdir: Path) -> None:
    output = run(write, workdir, faults=f"sensor_dead_axis={SOUND[0]},sensor_dead_axis_name=y")
    found = campaign_status(output, None)["early_check"]
    assert [(f["serial"], f["finding"], f["axis"]) for f in found] == [(SOUND[0], "dead_axis", "y")] * 2
    assert found[0]["value"] < 0.01 and found[0]["limit"] == 0.5


def test_drop_leaves_the_dut_out_of_the_fit_with_its_reason_and_its_poses_in_the_file(write, workdir: Path) -> None:
    output = run(write, workdir, "early_check: {action: drop}\n", faults=f"sensor_loose={LOOSE}")
    assert flagged(output) == [(LOOSE, 30.0, "loose_mount")]  # dropped: not judged again at 40 °C
    assert campaign_status(output, None)["early_check"][0]["action"] == "drop"
    calibration = load_calibration(output.with_suffix(".calibration.yaml"))
    assert set(calibration.of_quantity("acceleration")) == set(SOUND) | {TURNED}
    assert calibration.dropped[LOOSE].startswith(f"dropped by the early check: DUT {LOOSE} at +30 °C: residuals")
    stored = load_campaign(output)
    assert len(stored.poses) == 12 and all(LOOSE in [d.serial for d in p.duts] for p in stored.poses)


def test_a_finding_is_notified_as_early_check(write, workdir: Path, monkeypatch) -> None:
    sent: list[Notification] = []
    monkeypatch.setattr("accelcal_rig.engine.notify.Notifier.send", lambda self, n: sent.append(n))
    (workdir / "sim.yaml").write_text((workdir / "sim.yaml").read_text()
                                      + "notify: {command: [/bin/true], events: [early_check]}\n")
    run(write, workdir, faults=f"sensor_misoriented={TURNED}")
    assert [n.message.split(":")[0] for n in sent if n.event == "early_check"] == [
        f"DUT {TURNED} at +30 °C", f"DUT {TURNED} at +40 °C"]
