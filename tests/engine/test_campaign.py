"""The runner on a tiny procedure: its state sequence, and every abort path ending in the safe state."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import CampaignAborted
from accelcal_rig.instruments.interfaces import DeviceIdentity
from accelcal_rig.sim.devices import build_simulated_rig
from tests.conftest import TINY_PROCEDURE


def run_tiny(write, workdir: Path, tamper=None, text: str = TINY_PROCEDURE):
    """Run the tiny procedure; `tamper(instruments)` may break the simulated rig before it starts."""
    built = {}

    def factory(rig, procedure, clock, seed):
        instruments = build_simulated_rig(rig, procedure, clock, seed)
        if tamper:
            tamper(instruments)
        built["rig"] = instruments
        return instruments

    output = workdir / "run.h5"
    error = None
    try:
        run_campaign(prepare(write("tiny.yaml", text)), output, dry_run=True, seed=1, overwrite=False,
                     build_instruments=factory)
    except CampaignAborted as exc:
        error = exc
    return output, built["rig"], error


def events(path: Path, kind: str | None = None) -> list[str]:
    with h5py.File(path, "r") as f:
        kinds = [k.decode() for k in f["events/kind"][:]]
        messages = [m.decode() for m in f["events/message"][:]]
    return [m for k, m in zip(kinds, messages) if kind is None or k == kind]


def assert_safe(instruments, path: Path) -> None:
    assert instruments.chamber.read_setpoint_c() == 23.0
    assert all(not s.measuring for s in instruments.sensors)
    with h5py.File(path, "r") as f:
        assert f.attrs["state"] == "aborted"
        assert f.attrs["finished"]


def test_state_sequence_of_a_tiny_campaign(write, workdir: Path) -> None:
    output, _, error = run_tiny(write, workdir)
    assert error is None
    states = [m.split(" (")[0].split(" → ")[1] for m in events(output, "transition")]
    pose = ["move", "settle", "acquire", "store"]
    assert states == ["preflight", "ramp", "soak"] + pose * 6 + ["safe", "done"]
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done"
        assert f["poses/step_key"].shape == (6,)


def test_sensor_with_wrong_identity_aborts_before_anything_moves(write, workdir: Path) -> None:
    def wrong_part(instruments):
        instruments.sensors[2].identify = lambda: DeviceIdentity((0xAD, 0x1D, 0xE9), 1)  # an ADXL359

    output, instruments, error = run_tiny(write, workdir, wrong_part)
    assert error is not None
    assert "sensor ADX355-A003 (in-process virtual lab): identity AD/1D/E9 is not an ADXL355" in str(error)
    assert_safe(instruments, output)
    with h5py.File(output, "r") as f:
        assert f["poses/step_key"].shape == (0,)
        assert "identity AD/1D/E9" in f.attrs["abort_reason"]


def test_chamber_that_never_reaches_its_setpoint_times_out(write, workdir: Path) -> None:
    def stuck(instruments):
        instruments.chamber.read_temperature_c = lambda: 23.0

    output, instruments, error = run_tiny(write, workdir, stuck)
    assert "reaching 30 °C: not reached within" in str(error)
    assert_safe(instruments, output)


def test_interrupt_mid_campaign_keeps_every_stored_pose(write, workdir: Path) -> None:
    def interrupt_on_fourth_pose(instruments):
        sensor = instruments.sensors[0]
        original, calls = sensor.acquire, []

        def acquire(n):
            calls.append(n)
            if len(calls) == 4:
                raise KeyboardInterrupt
            return original(n)

        sensor.acquire = acquire

    output, instruments, error = run_tiny(write, workdir, interrupt_on_fourth_pose)
    assert isinstance(error.__cause__, KeyboardInterrupt)
    assert "interrupted by operator" in str(error)
    assert_safe(instruments, output)
    with h5py.File(output, "r") as f:
        assert [k.decode() for k in f["poses/step_key"][:]] == ["T30/pose01", "T30/pose02", "T30/pose03"]
        for serial in f["duts"]:
            assert f[f"duts/{serial}/accel/raw_codes"].shape == (3, 20, 3)
            assert np.all(np.isfinite(f[f"duts/{serial}/accel/mean"][:]))


def test_one_failing_device_does_not_keep_the_others_unsafe(write, workdir: Path) -> None:
    def broken(instruments):
        def fail(*_):
            raise OSError("serial port gone")

        instruments.sensors[1].acquire = fail
        instruments.turntable.stop = fail

    output, instruments, error = run_tiny(write, workdir, broken)
    assert "OSError: serial port gone" in str(error)
    assert_safe(instruments, output)  # chamber and every sensor still made safe
    safe_events = events(output, "safe")
    assert any("FAILED: turntable" in m and "serial port gone" in m for m in safe_events)


def test_soak_that_never_settles_stores_its_trace_and_aborts(write, workdir: Path) -> None:
    text = TINY_PROCEDURE.replace("timeout_min: 120", "timeout_min: 30").replace("band_c: 0.3", "band_c: 0.01")
    output, instruments, error = run_tiny(write, workdir, text=text)
    assert "T30: DUT temperatures stable within 0.01 °C: not reached within 0:30:00" in str(error)
    assert_safe(instruments, output)
    with h5py.File(output, "r") as f:
        soak = f["soaks/T30"]
        assert soak.attrs["outcome"] == "timeout"
        assert soak["dut_c"].shape[1] == 4 and soak["t_s"].shape[0] > 100


def test_chamber_alarm_during_the_soak_aborts(write, workdir: Path) -> None:
    def alarm_after_ten_minutes(instruments):
        lab_clock = instruments.chamber.lab.clock
        instruments.chamber.alarm_active = lambda: lab_clock.now() > 600

    output, instruments, error = run_tiny(write, workdir, alarm_after_ten_minutes)
    assert "chamber (in-process virtual lab): controller alarm active" in str(error)
    assert_safe(instruments, output)
    with h5py.File(output, "r") as f:
        assert f["soaks/T30"].attrs["outcome"] == "fault"
        assert np.isnan(f["soaks/T30"].attrs["t_stable_s"])


def test_same_seed_same_data_other_seed_other_noise(write, workdir: Path) -> None:
    def raw_codes(seed: int, name: str) -> np.ndarray:
        output = workdir / name
        run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), output, dry_run=True, seed=seed, overwrite=False)
        with h5py.File(output, "r") as f:
            return f["duts/ADX355-A001/accel/raw_codes"][:]

    first, again, other = raw_codes(5, "a.h5"), raw_codes(5, "b.h5"), raw_codes(6, "c.h5")
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)
    # Different noise, same sensor: the pose means agree within a few standard errors (0.2 mg / √20).
    np.testing.assert_allclose(first.mean(axis=1), other.mean(axis=1), atol=5 * 0.2e-3 * 256000 / np.sqrt(20))


def test_second_interrupt_during_the_safe_state_skips_no_device(write, workdir: Path) -> None:
    def interrupt_twice(instruments):
        def interrupt(*_):
            raise KeyboardInterrupt

        instruments.sensors[0].acquire = interrupt
        instruments.turntable.stop = interrupt  # the operator presses Ctrl-C again while the rig is made safe

    output, instruments, error = run_tiny(write, workdir, interrupt_twice)
    assert isinstance(error.__cause__, KeyboardInterrupt)
    assert_safe(instruments, output)
    assert any("FAILED: turntable" in m and "KeyboardInterrupt" in m for m in events(output, "safe"))


def test_fit_stage_runs_after_the_safe_state(write, workdir: Path) -> None:
    output = workdir / "run.h5"
    text = TINY_PROCEDURE + "fit: {mode: reference, polynomial_degree: 0}\n"
    result = run_campaign(prepare(write("tiny.yaml", text)), output, dry_run=True, seed=1, overwrite=False,
                          calibration=workdir / "cal.yaml")
    assert not result.summary.fit_failed and "calibration → " in result.summary.fit
    states = [m.split(" (")[0].split(" → ")[1] for m in events(output, "transition")]
    assert states[-3:] == ["safe", "fit", "done"]
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done" and "fit" not in f  # derived results live in their own file
    assert (workdir / "cal.yaml").exists()


def test_a_fit_that_cannot_write_its_file_leaves_the_campaign_done(write, workdir: Path) -> None:
    output = workdir / "run.h5"
    result = run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), output, dry_run=True, seed=1,
                          overwrite=False, calibration=workdir / "gone" / "cal.yaml")
    assert result.summary.fit_failed and "No such file or directory" in result.summary.fit
    with h5py.File(output, "r") as f:
        assert f.attrs["state"] == "done" and f["poses/step_key"].shape == (6,)
