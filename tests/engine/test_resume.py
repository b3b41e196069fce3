"""Resuming a campaign: every pose of the plan stored exactly once, whatever stopped the last run."""

from __future__ import annotations

import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.resume import first_difference
from accelcal_rig.engine.session import NothingToResume
from accelcal_rig.errors import CampaignAborted, ConfigError
from accelcal_rig.sim.devices import build_simulated_rig
from tests.conftest import kill_mid_pose, stored_poses
from tests.engine.test_campaign import events

TWO_SETPOINTS = """\
name: two
rig: sim.yaml
setpoints_c: [20, 30]
soak: {min_dwell_min: 5, window_min: 2, band_c: 0.3, poll_s: 10, timeout_min: 120}
schedule: {kind: six-position}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
"""


def run(procedure: Path, output: Path, *, resume: bool = False, fail_at_pose: int | None = None):
    """Run (or resume) on the in-process rig; with `fail_at_pose`, the turntable breaks at that move."""
    built = {}

    def factory(rig, procedure_model, clock, seed):
        instruments = build_simulated_rig(rig, procedure_model, clock, seed)
        if fail_at_pose is not None:
            moves, real_move = [0], instruments.turntable.move_to

            def failing_move(angles):
                moves[0] += 1
                if moves[0] == fail_at_pose:
                    raise OSError("turntable link lost")
                real_move(angles)

            instruments.turntable.move_to = failing_move
        built["rig"] = instruments
        return instruments

    run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False, build_instruments=factory,
                 resume=resume)
    return built["rig"]


def stored_keys(path: Path) -> list[str]:
    with h5py.File(path, "r") as f:
        return [k.decode() for k in f["poses/step_key"][:]]


def plan_pose_keys(path: Path) -> list[str]:
    with h5py.File(path, "r") as f:
        return [k.decode() for k, kind in zip(f["plan/step_key"][:], f["plan/kind"][:]) if kind == b"pose"]


def test_an_aborted_campaign_resumes_from_the_first_pose_not_stored(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted, match="turntable link lost"):
        run(procedure, output, fail_at_pose=9)
    assert len(stored_keys(output)) == 8
    run(procedure, output, resume=True)
    keys = stored_keys(output)
    assert sorted(keys) == sorted(plan_pose_keys(output)) and len(set(keys)) == len(keys) == 12
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done" and f.attrs["runs"] == 2 and f.attrs["abort_reason"] == ""
        for serial in f["duts"]:
            assert f[f"duts/{serial}/accel/raw_codes"].shape[0] == 12
        assert sorted(f["soaks"]) == ["T20", "T30", "T30#2"]  # the interrupted setpoint soaked again
        t = f["poses/t_start_s"][:]
        assert np.all(np.diff(t) > 0)  # the resumed run's clock goes on from where the file ended
    messages = events(output)
    assert any("run 2 resumes after 8 stored poses (the last run left the file 'aborted')" in m for m in messages)
    assert any("T20: every pose already stored" in m for m in messages)
    assert not any("safe state first" in m for m in messages)  # the abort had made it safe


def test_a_run_that_died_mid_pose_is_cut_back_and_made_safe_first(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output, fail_at_pose=5)
    kill_mid_pose(output, 3)  # what kill -9 in the middle of storing the fourth pose leaves
    before = stored_poses(output)
    assert len(before) == 3
    instruments = run(procedure, output, resume=True)
    keys = stored_keys(output)
    assert sorted(keys) == sorted(plan_pose_keys(output)) and len(set(keys)) == 12
    after = stored_poses(output)
    assert all(after[key] == data for key, data in before.items())  # stored before the kill: untouched
    messages = events(output)
    assert any(re.fullmatch(r"\d+ bytes after the journal's last whole record \(a record the run that died was "
                            r"writing, or a damaged one\) cut off, kept as c\.h5\.journal\.tail-\d{8}T\d{6}", m)
               for m in messages)
    resumed = next(i for i, m in enumerate(messages) if "run 2 resumes after 3 stored poses" in m)
    safe_first = next(i for i, m in enumerate(messages) if "safe state first" in m)
    preflight = next(i for i, m in enumerate(messages) if "→ preflight" in m and i > resumed)
    assert resumed < safe_first < preflight  # the rig is made safe before anything else is done with it
    assert instruments.chamber.read_setpoint_c() == 23.0  # safe again at the end


def test_resume_refuses_a_changed_procedure_and_names_the_key(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output, fail_at_pose=3)
    changed = write("two.yaml", TWO_SETPOINTS.replace("band_c: 0.3", "band_c: 0.2"))
    with pytest.raises(ConfigError, match=r"two.yaml:4: soak.band_c: is 0.2 but the campaign in .* was started "
                                          r"with 0.3; resume with the same procedure"):
        run(changed, output, resume=True)
    assert len(stored_keys(output)) == 2  # untouched


def test_resume_accepts_new_ports_but_not_another_fixture(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output, fail_at_pose=3)
    rig = (workdir / "sim.yaml").read_text()
    write("sim.yaml", rig.replace("chamber:\n", "chamber:\n  timeout_s: 3.0\n", 1))
    run(procedure, output, resume=True)  # a connection detail: accepted
    assert len(stored_keys(output)) == 12
    with pytest.raises(NothingToResume):
        run(procedure, output, resume=True)
    output2 = workdir / "d.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output2, fail_at_pose=3)
    write("sim.yaml", rig.replace("mount_euler_deg: [0, 0, 90]", "mount_euler_deg: [0, 0, 45]", 1))
    with pytest.raises(ConfigError, match=r"sim.yaml:\d+: fixture.sensors\[1\].mount_euler_deg\[2\]: is 45"):
        run(procedure, output2, resume=True)


def test_resume_without_a_file_starts_the_campaign(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "new.h5"
    run(procedure, output, resume=True)
    assert len(stored_keys(output)) == 12


def test_first_difference_skips_connection_keys() -> None:
    old = {"chamber": {"endpoint": "a", "limits": [1, 2]}, "sensors": [{"serial": "x", "baudrate": 9600}]}
    assert first_difference(old, {"chamber": {"endpoint": "b", "limits": [1, 2]},
                                  "sensors": [{"serial": "x", "baudrate": 115200}]}, frozenset({"endpoint", "baudrate"})) is None
    assert first_difference(old, {"chamber": {"endpoint": "a", "limits": [1, 3]}, "sensors": old["sensors"]},
                            frozenset()) == (("chamber", "limits", 1), 2, 3)


def never_stable_at_20(instruments) -> None:
    """DUT temperatures that wander by 1 °C while the chamber is at 20 °C (a soak there never settles)."""
    for sensor in instruments.sensors:
        real = sensor.read_temperature_c
        flip = [0.0]

        def wandering(real=real, flip=flip) -> float:
            value = real()
            if abs(instruments.chamber.read_setpoint_c() - 20.0) < 0.01:
                flip[0] = 1.0 - flip[0]
                return value + flip[0]
            return value

        sensor.read_temperature_c = wandering


def run_with(procedure: Path, output: Path, tamper, resume: bool = False) -> None:
    def factory(rig, procedure_model, clock, seed):
        instruments = build_simulated_rig(rig, procedure_model, clock, seed)
        tamper(instruments)
        return instruments

    run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False, build_instruments=factory,
                 resume=resume)


@pytest.mark.parametrize("policy", ["skip", "proceed"])
def test_a_soak_that_times_out_is_skipped_or_measured_as_the_procedure_says(write, workdir: Path, policy) -> None:
    text = TWO_SETPOINTS.replace("timeout_min: 120", f"timeout_min: 30, on_timeout: {policy}")
    procedure, output = write("two.yaml", text), workdir / "c.h5"
    run_with(procedure, output, never_stable_at_20)
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done"
        assert f["soaks/T20"].attrs["outcome"] == "timeout" and f["soaks/T30"].attrs["outcome"] == "stable"
        setpoints = f["poses/setpoint_c"][:]
    warnings = [m for m in events(output, "soak") if "not reached within 0:30:00" in m]
    if policy == "skip":
        assert sorted(set(setpoints)) == [30.0] and len(setpoints) == 6
        assert warnings == ["T20: DUT temperatures stable within 0.3 °C: not reached within 0:30:00; setpoint "
                            "skipped, its 6 poses not measured (soak.on_timeout: skip)"]
        run_with(procedure, output, lambda instruments: None, resume=True)  # chamber fixed: resume retries T20
        assert sorted(stored_keys(output)) == sorted(plan_pose_keys(output))
    else:
        assert sorted(set(setpoints)) == [20.0, 30.0] and len(setpoints) == 12
        assert len(warnings) == 1 and warnings[0].endswith("measuring its poses anyway (soak.on_timeout: proceed)")


def test_a_resume_that_cannot_connect_keeps_the_last_abort_reason(write, workdir: Path) -> None:
    procedure, output = write("two.yaml", TWO_SETPOINTS), workdir / "c.h5"
    with pytest.raises(CampaignAborted):
        run(procedure, output, fail_at_pose=3)

    def unreachable(rig, procedure_model, clock, seed):
        raise ConfigError("chamber (modbus-tcp 10.0.0.9:502): cannot connect")

    with pytest.raises(ConfigError, match="cannot connect"):
        run_campaign(prepare(procedure), output, dry_run=True, seed=1, overwrite=False,
                     build_instruments=unreachable, resume=True)
    with h5py.File(output, "r") as f:
        assert "turntable link lost" in f.attrs["abort_reason"] and f.attrs["finished"]
    run(procedure, output, resume=True)
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done" and f.attrs["abort_reason"] == "" and f.attrs["runs"] == 3
