"""Faults injected into the wire-level simulators: transient ones are retried and the campaign completes
with every pose stored once; persistent ones end in the safe state, recorded in the file."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from accelcal_rig.assembly import WiredRig
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.engine.session import run_campaign
from accelcal_rig.errors import CampaignAborted
from accelcal_rig.sim.wire_rig import SimulatedRig
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE
from tests.engine.test_campaign import events

#: Short wire timeouts: the simulators answer in a millisecond, and a dropped reply costs one timeout.
FAST_TIMEOUTS = {"chamber:\n": "chamber:\n  timeout_s: 0.3\n", "turntable:\n": "turntable:\n  timeout_s: 0.3\n"}


def fast_rig(workdir: Path) -> None:
    rig = (workdir / "sim.yaml").read_text()
    for old, new in FAST_TIMEOUTS.items():
        rig = rig.replace(old, new, 1)
    rig = rig.replace("name: dut1}", "name: dut1, timeout_s: 0.3}").replace("name: dut2,", "name: dut2, timeout_s: 0.3,")
    rig = rig.replace("name: dut3,", "name: dut3, timeout_s: 0.3,").replace("name: dut4,", "name: dut4, timeout_s: 0.3,")
    (workdir / "sim.yaml").write_text(rig + "retry: {attempts: 8}\n")


def run_wired(write, workdir: Path, faults: str) -> tuple[Path, SimulatedRig, CampaignAborted | None]:
    """A dry run through the wires with `faults`; returns the simulated rig to inspect its last commands."""
    fast_rig(workdir)
    prepared = prepare(write("tiny.yaml", TINY_PROCEDURE), faults=faults)
    wired = WiredRig(prepared.rig, prepared.procedure.model.simulation, dry_run=True)
    output, error = workdir / "run.h5", None
    try:
        run_campaign(prepared, output, wired, seed=2, overwrite=False)
    except CampaignAborted as exc:
        error = exc
    assert wired.served is not None
    return output, wired.served, error


def test_transient_faults_are_retried_and_every_pose_is_stored_once(write, workdir: Path) -> None:
    output, rig, error = run_wired(write, workdir, "rate=0.1,seed=3")
    assert error is None
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done" and f["poses/step_key"].shape[0] == 6
    assert load_campaign(output).integrity_problems() == []
    retries = events(output, "retry")
    assert len(retries) >= 10
    for instrument in ("chamber (modbus-tcp", "turntable (serial", "sensor bridge (serial"):
        assert any(m.startswith(instrument) for m in retries), instrument
    assert any("no reply within the timeout" in m for m in retries)
    assert any("garbled" in m or "answered" in m or "unexpected reply" in m for m in retries)


def test_torn_temperature_reads_do_not_reach_the_soak_or_the_poses(write, workdir: Path) -> None:
    output, _, error = run_wired(write, workdir, "sensor_temperature_tear_rate=0.02")
    assert error is None
    soak = load_campaign(output).soaks[0]
    # Every poll of every DUT through the driver: no step of a torn read's ~28 °C between polls.
    assert soak.outcome == "stable" and len(soak.dut_c) > 20 and np.abs(np.diff(soak.dut_c, axis=0)).max() < 1.0


def assert_safe_and_recorded(output: Path, rig: SimulatedRig, error: CampaignAborted | None, reason: str) -> None:
    assert error is not None and reason in str(error)
    assert rig.chamber.last_setpoint_c == 23.0  # what the simulator last heard: the safe setpoint
    assert rig.turntable.last_command == "STOP"
    assert all(not bridge.device.measuring for bridge in rig.bridges.values())
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "aborted" and reason in f.attrs["abort_reason"]
    assert load_campaign(output).integrity_problems() == []


@pytest.mark.parametrize(("faults", "reason"), [
    ("chamber_stall_after_min=0", "reaching 30 °C: not reached within"),
    ("turntable_stall_after_min=0", "turntable (serial /dev/pts/"),
    ("sensor_wrong_id=ADX355-A002", "identity AD/1D/E9 is not an ADXL355"),
    ("sensor_stuck=ADX355-A003", "data stuck"),
])
def test_persistent_faults_end_in_the_safe_state(write, workdir: Path, faults: str, reason: str) -> None:
    output, rig, error = run_wired(write, workdir, faults)
    assert_safe_and_recorded(output, rig, error, reason)


def test_instruments_that_never_answer_are_refused_before_the_campaign_starts(write, workdir: Path) -> None:
    from accelcal_rig.errors import InstrumentError

    with pytest.raises(InstrumentError, match=r"sensor bridge \(serial /dev/pts/\d+\): '\?': no reply within the timeout"):
        run_wired(write, workdir, "rate=1,kinds=drop")
    assert not (workdir / "run.h5").exists()


@pytest.mark.parametrize(("stop", "at_pose"), [(KeyboardInterrupt, 2), (SystemExit, 5)])
def test_a_stop_mid_campaign_leaves_the_simulators_safe(write, workdir: Path, monkeypatch, stop, at_pose) -> None:
    """As a signal surfaces (stop_when_safe raises it between two poses): the simulators at the far end of
    the wires last heard the safe setpoint and a STOP, and every sensor is in standby."""
    from accelcal_rig.store.writer import CampaignWriter

    real_append, stored = CampaignWriter.append_pose, []

    def append_then_stop(self, pose):
        real_append(self, pose)
        stored.append(pose.step_key)
        if len(stored) == at_pose:
            raise stop()

    monkeypatch.setattr(CampaignWriter, "append_pose", append_then_stop)
    output, rig, error = run_wired(write, workdir, "rate=0")
    assert error is not None
    assert rig.chamber.last_setpoint_c == 23.0 and rig.turntable.last_command == "STOP"
    assert all(not bridge.device.measuring for bridge in rig.bridges.values())
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "aborted" and f["poses/step_key"].shape[0] == at_pose


def test_a_setpoint_beyond_the_controllers_own_limits_is_refused_before_anything_moves(write, workdir: Path,
                                                                                      capsys) -> None:
    from accelcal_rig.cli import main

    rig = (workdir / "sim.yaml").read_text().replace("profile: watlow-f4t", "profile: watlow-f4")
    (workdir / "sim.yaml").write_text(rig.replace("simulation:\n", "simulation:\n  controller_limits_c: [-20, 25]\n"))
    assert main(["check", str(workdir / "sim.yaml"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "set point limits: the rig's -55…100 °C, the controller's -20…25 °C" in out
    output = workdir / "c.h5"
    assert main(["run", str(write("tiny.yaml", TINY_PROCEDURE)), "--dry-run", "-o", str(output), "-q"]) == 1
    assert "30 °C is beyond the controller's own set point limits -20…25 °C" in capsys.readouterr().err
    campaign = load_campaign(output)
    assert campaign.state == "aborted" and not campaign.poses
    assert any("the controller's own set point limits -20…25 °C" in e.message for e in campaign.events)
