"""The `rig` command: a whole dry run through the installed console script, and its one-line errors."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from tests.conftest import REPO, TINY_PROCEDURE


def rig(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    beside_python = Path(sys.executable).parent / "rig"  # the venv's scripts, activated or not
    executable = str(beside_python) if beside_python.exists() else shutil.which("rig")
    assert executable, "the console script `rig` is installed with the package"
    return subprocess.run([executable, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_quick_6pos_dry_run_end_to_end(tmp_path: Path) -> None:
    run = rig("run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", "quick.h5", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "campaign done: quick-6pos" in run.stdout
    assert "12 of 12 × 4 DUTs × 200 samples" in run.stdout
    assert "calibration → quick.calibration.yaml" in run.stdout
    assert (tmp_path / "quick.calibration.yaml").exists()
    assert "T35: stable after" in run.stderr  # progress while it runs
    # Not a terminal: every line carries the wall-clock time, and progress lines come at each phase.
    assert all(re.match(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d (INFO|WARNING|ERROR) ", line) for line in run.stderr.splitlines())
    assert re.search(r"progress: T35 \(2/2\) soak .* · pose 6/12 · \d+:\d\d:\d\d left", run.stderr)
    log = (tmp_path / "quick.h5.log").read_text()
    assert log.count("stored") >= 12 and "progress: T15 (1/2) poses" in log
    status = rig("status", "quick.h5", "--json", cwd=tmp_path)
    assert status.returncode == 0
    report = json.loads(status.stdout)
    assert report["state"] == "done"
    assert (report["poses_done"], report["poses_total"], report["samples_per_pose"]) == (12, 12, 200)
    assert report["duts"] == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]
    assert report["setpoints_c"] == [15.0, 35.0]
    assert report["started"] and report["finished"]


def one_line_error(capsys, argv: list[str], expected_code: int) -> str:
    assert main(argv) == expected_code
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_broken_yaml_is_one_line_with_exit_2(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("schedule: {kind: six-position}", "schedule: {kind: six"))
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(path.with_suffix(".h5"))], 2)
    assert f"{path}:" in err and "syntax" in err


def test_invalid_value_is_one_line_with_exit_2(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("samples_per_pose: 20", "samples_per_pose: lots"))
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(path.with_suffix(".h5"))], 2)
    assert f"{path}:6: acquisition.samples_per_pose:" in err
    assert not path.with_suffix(".h5").exists()  # nothing created, nothing moved


def test_existing_campaign_is_never_overwritten_silently(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE)
    output = path.with_suffix(".h5")
    output.write_bytes(b"last night's campaign")
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(output)], 2)
    assert "exists" in err and output.read_bytes() == b"last night's campaign"


def test_without_dry_run_a_rig_without_endpoints_is_refused(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE)
    err = one_line_error(capsys, ["run", str(path), "-o", str(path.with_suffix(".h5"))], 2)
    assert "sim.yaml:" in err and "chamber.endpoint: no endpoint given" in err and "--dry-run" in err
    assert not path.with_suffix(".h5").exists()


@pytest.mark.parametrize("content", [None, b"not hdf5"])
def test_status_of_a_missing_or_foreign_file(tmp_path: Path, capsys, content: bytes | None) -> None:
    path = tmp_path / "x.h5"
    if content is not None:
        path.write_bytes(content)
    err = one_line_error(capsys, ["status", str(path)], 2)
    assert str(path) in err


def test_every_command_has_help_with_an_example(capsys) -> None:
    import argparse

    from accelcal_rig.cli.parser import build_parser as _build_parser

    commands = next(a for a in _build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert {"run", "plan", "resume", "status", "check", "sim", "fit", "report", "export"} <= set(commands)
    for command in commands:
        with pytest.raises(SystemExit) as exit_info:
            main([command, "--help"])
        assert exit_info.value.code == 0
        out = capsys.readouterr().out
        assert f"example:\n  rig {command} " in out, command


def test_config_option_overrides_the_procedures_rig(write, workdir: Path, capsys) -> None:
    procedure = write("tiny.yaml", TINY_PROCEDURE.replace("rig: sim.yaml", "rig: missing.yaml"))
    rig_text = (workdir / "sim.yaml").read_text()
    two_duts = rig_text.split("    - {serial: ADX355-A003")[0] + rig_text[rig_text.index("\nsimulation:"):]
    other = write("two-duts.yaml", two_duts)
    output = workdir / "out.h5"
    assert main(["run", str(procedure), "--config", str(other), "--dry-run", "-o", str(output), "-q"]) == 0
    assert "6 of 6 × 2 DUTs" in capsys.readouterr().out


def test_missing_output_folder_is_one_line(write, workdir: Path, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE)
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(workdir / "no" / "such.h5")], 2)
    assert "does not exist" in err


def test_sigterm_mid_campaign_reaches_the_safe_state_and_keeps_the_poses(tmp_path: Path) -> None:
    import signal
    import time

    import h5py

    beside_python = Path(sys.executable).parent / "rig"
    process = subprocess.Popen([str(beside_python), "run", str(REPO / "procedures" / "paper-24pos-thermal.yaml"),
                                "--dry-run", "-o", "c.h5"], cwd=tmp_path, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    log = tmp_path / "c.h5.log"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (log.exists() and "T-30: stable" in log.read_text()):
        time.sleep(0.02)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert err.strip().splitlines()[-1] == ("rig: campaign aborted, rig in safe state: terminated by signal (SIGTERM); "
                                            "continue it with: rig resume c.h5")
    with h5py.File(tmp_path / "c.h5", "r") as f:
        assert f.attrs["state"] == "aborted"
        stored = f["poses/step_key"].shape[0]
        assert 24 <= stored < 264
        for dut in f["duts"].values():
            assert dut["accel/raw_codes"].shape[0] == stored
        safe = [m.decode() for m, k in zip(f["events/message"][:], f["events/kind"][:]) if k.decode() == "safe"]
    assert any("chamber" in m and "to 23 °C" in m for m in safe)
    assert sum("standby" in m for m in safe) == 4


def test_rig_fit_json_report_and_calibration_file(paper_campaign: Path, tmp_path: Path, capsys) -> None:
    campaign = tmp_path / "campaign.h5"
    shutil.copy(paper_campaign, campaign)
    calibration = tmp_path / "cal.yaml"
    assert main(["fit", str(campaign), "-o", str(calibration), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert sorted(report) == ["ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"]
    for dut in report.values():
        sensor = dut["channels"]["accel"]
        for key in ("rmse_before_mg", "rmse_after_mg", "rmse_by_setpoint", "drift_before_mg", "drift_after_mg",
                    "noise_floor_mg", "truth_error"):
            assert key in sensor
        assert set(sensor["rmse_by_setpoint"][0]) >= {"setpoint_c", "before_mg", "polynomial_mg", "measurement_mg"}
        assert len(sensor["drift_after_mg"]) == 3
    from accelcal_rig.fit.calibration import load_calibration

    loaded = load_calibration(calibration)
    assert loaded.source["campaign"] == str(campaign) and len(loaded.source["measurements_sha256"]) == 64


def test_rig_fit_refuses_a_campaign_still_running(paper_campaign: Path, tmp_path: Path, capsys) -> None:
    import hashlib

    campaign = tmp_path / "campaign.h5"
    shutil.copy(paper_campaign, campaign)
    holder = subprocess.Popen(  # another process holding the campaign, as a running campaign does
        [sys.executable, "-c", "import sys, time; from pathlib import Path; from accelcal_rig.store.lock import acquire; "
                               f"acquire(Path({str(campaign)!r}), 'rig run'); print('held', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True)
    digest = hashlib.sha256(campaign.read_bytes()).hexdigest()
    try:
        assert holder.stdout.readline().strip() == "held"
        err = one_line_error(capsys, ["fit", str(campaign), "-o", str(tmp_path / "cal.yaml")], 2)
    finally:
        holder.kill()
        holder.wait()
    assert f"a campaign is running on it, pid {holder.pid} on " in err
    assert hashlib.sha256(campaign.read_bytes()).hexdigest() == digest and not (tmp_path / "cal.yaml").exists()


def test_rig_fit_on_a_file_without_poses_is_one_line(write, workdir: Path, capsys) -> None:
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare
    from accelcal_rig.errors import CampaignAborted

    campaign = workdir / "empty.h5"

    def no_sensors_answer(rig, procedure, clock, seed):
        from accelcal_rig.sim.devices import build_simulated_rig

        instruments = build_simulated_rig(rig, procedure, clock, seed)
        instruments.sensors[0].identify = lambda: (_ for _ in ()).throw(OSError("bridge not answering"))
        return instruments

    with pytest.raises(CampaignAborted):
        run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), campaign, dry_run=True, seed=0, overwrite=False,
                     build_instruments=no_sensors_answer)
    err = one_line_error(capsys, ["fit", str(campaign), "-o", str(workdir / "cal.yaml")], 2)
    assert "the campaign is aborted (" in err and ", 0 of 6 poses stored, next " in err
    err = one_line_error(capsys, ["fit", str(campaign), "-o", str(workdir / "cal.yaml"), "--partial"], 1)
    assert "no poses stored, nothing to fit" in err


def test_a_signal_before_the_campaign_starts_is_one_line_and_leaves_no_file(write, capsys, monkeypatch) -> None:
    from accelcal_rig import assembly
    from accelcal_rig.core.signals import TerminationRequested

    def terminated(*_):
        raise TerminationRequested()

    monkeypatch.setattr(assembly, "connect_rig", terminated)  # SIGTERM while connecting to the instruments
    path = write("tiny.yaml", TINY_PROCEDURE)
    before = sorted(path.parent.iterdir())
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(path.with_suffix(".h5"))], 130)
    assert "interrupted before the campaign started" in err
    assert sorted(path.parent.iterdir()) == before  # no campaign, no lock, no log


def dead_rig(workdir: Path) -> Path:
    """The simulated rig's config wired to ports nothing answers on: a closed TCP port, serial devices that
    do not exist."""
    import yaml

    config = yaml.safe_load((workdir / "sim.yaml").read_text())
    config["chamber"]["endpoint"] = "127.0.0.1:1"
    config["turntable"]["endpoint"] = str(workdir / "no-turntable")
    for sensor in config["fixture"]["sensors"]:
        sensor["endpoint"] = str(workdir / f"no-{sensor['serial']}")
    (workdir / "dead.yaml").write_text(yaml.safe_dump(config))
    return workdir / "dead.yaml"


def test_a_run_that_cannot_reach_its_rig_leaves_no_file_and_an_old_campaigns_log_intact(write, workdir: Path,
                                                                                       capsys) -> None:
    procedure, config = write("tiny.yaml", TINY_PROCEDURE), dead_rig(workdir)
    before = sorted(workdir.iterdir())
    err = one_line_error(capsys, ["run", str(procedure), "--config", str(config), "-o", str(workdir / "c.h5")], 2)
    assert err.startswith("rig: error: chamber (modbus-tcp 127.0.0.1:1): cannot connect")
    assert sorted(workdir.iterdir()) == before  # no lock, no log
    assert main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5"), "-q"]) == 0
    capsys.readouterr()
    kept = {path.name: path.read_bytes() for path in workdir.glob("c.h5*") if path.is_file()}
    assert "c.h5.log" in kept and "c.h5.lock" in kept
    one_line_error(capsys, ["run", str(procedure), "--config", str(config), "-o", str(workdir / "c.h5"),
                            "--overwrite"], 2)
    assert {path.name: path.read_bytes() for path in workdir.glob("c.h5*") if path.is_file()} == kept


@pytest.mark.parametrize("kill_after_s", [0.0, 0.15])
def test_kill_9_then_resume_stores_every_pose_exactly_once(tmp_path: Path, kill_after_s: float) -> None:
    """Killed at two moments after the first soak (the benchmark kills the paper campaign at random ones)."""
    import signal
    import time

    import h5py

    from accelcal_rig.store.read import load_campaign

    beside_python = Path(sys.executable).parent / "rig"
    process = subprocess.Popen([str(beside_python), "run", str(REPO / "procedures" / "quick-6pos.yaml"),
                                "--dry-run", "-o", "c.h5"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    log = tmp_path / "c.h5.log"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (log.exists() and "T15: stable" in log.read_text()):
        time.sleep(0.01)
    time.sleep(kill_after_s)
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=10)
    with h5py.File(tmp_path / "c.h5", "r") as f:  # readable as the kill left it
        assert f.attrs["state"] in ("created", "running")
    status = json.loads(rig("status", "c.h5", "--json", cwd=tmp_path).stdout)
    assert status["writer"].startswith("gone (pid")
    resumed = rig("resume", "c.h5", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert "12 of 12 × 4 DUTs" in resumed.stdout
    with h5py.File(tmp_path / "c.h5", "r") as f:
        assert f.attrs["state"] == "done" and f.attrs["runs"] == 2
        assert f["poses/step_key"].shape[0] == 12
    assert load_campaign(tmp_path / "c.h5").integrity_problems() == []
    assert "run 2 resumes" in (tmp_path / "c.h5.log").read_text()  # the log goes on, not replaced
    assert "rig resume" not in rig("status", "c.h5", cwd=tmp_path).stdout


def test_resume_of_a_foreign_file_or_bad_faults_is_one_line(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE)
    output = path.with_suffix(".h5")
    output.write_bytes(b"last night's campaign")
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(output), "--resume"], 2)
    assert "not a readable HDF5 file" in err and output.read_bytes() == b"last night's campaign"
    err = one_line_error(capsys, ["run", str(path), "--dry-run", "-o", str(path.with_suffix(".x.h5")),
                                  "--faults", "rate=0.1,colour=red"], 2)
    assert "--faults: 'colour=red': expected key=value" in err


def test_resume_of_a_complete_campaign_says_so_and_exits_0(write, capsys) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE)
    output = path.with_suffix(".h5")
    assert main(["run", str(path), "--dry-run", "-o", str(output), "-q"]) == 0
    capsys.readouterr()
    assert main(["resume", str(output), "-q"]) == 0
    assert "the campaign is complete: every pose is stored" in capsys.readouterr().out


def test_rig_plan_prints_every_pose_and_an_estimate_without_touching_instruments(write, workdir: Path, capsys) -> None:
    rig_text = (workdir / "sim.yaml").read_text().replace("driver: modbus-tcp\n", "driver: modbus-tcp\n  endpoint: 127.0.0.1:9\n")
    (workdir / "sim.yaml").write_text(rig_text)  # an endpoint nobody answers: plan must not care
    path = write("tiny.yaml", TINY_PROCEDURE)
    assert main(["plan", str(path)]) == 0
    out = capsys.readouterr().out
    assert "setpoints  1, in this order: 30 °C" in out and "poses      6 per setpoint (six-position)" in out
    pose_rows = [line for line in out.splitlines() if re.match(r"^\s+[1-6]\s+-?\d", line)]
    assert len(pose_rows) == 6 and all(len(row.split()) == 1 + 3 + 3 for row in pose_rows)
    assert re.search(r"^\s+T30\s+\d:\d\d:\d\d\s+\d:\d\d:\d\d\s+\d:\d\d:\d\d\s+\d:\d\d:\d\d", out, re.M)
    assert re.search(r"^estimated duration \d+:\d\d:\d\d ", out, re.M)
    assert main(["plan", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert len(report["poses"]) == 6 and report["poses_total"] == 6
    assert report["estimate"]["total_s"] == pytest.approx(sum(
        s["ramp_s"] + s["soak_s"] + s["poses_s"] for s in report["estimate"]["setpoints"]))


@pytest.mark.parametrize(("procedure", "method", "said"), [
    ("paper-24pos-thermal.yaml", "soak", "hysteresis"),
    ("paper-24pos-ramp.yaml", "ramp", "one direction only"),
    ("fast-bidirectional-ramp.yaml", "bidirectional ramp", "cancel in the joint fit"),
])
def test_rig_plan_says_which_method_and_what_it_cancels(procedure: str, method: str, said: str, capsys) -> None:
    assert main(["plan", str(REPO / "procedures" / procedure), "--json"]) == 0
    explained = json.loads(capsys.readouterr().out)["method"]
    assert explained["name"] == method and said in explained["cancels"] + explained["does_not_cancel"]
    assert main(["plan", str(REPO / "procedures" / procedure)]) == 0
    out = capsys.readouterr().out
    assert f"method     {method}:" in out and "expected accurate because" in out and "not cancelled:" in out


def test_rig_plan_shows_verification_limits_and_warns_of_too_few_setpoints(write, capsys) -> None:
    text = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [20, 40]") + (
        "fit: {polynomial_degree: 2}\nverify: {schedule: {kind: sphere, count: 8}, setpoints_c: [30]}\n"
        "acceptance: {max_drift_mg: 0.2}\n")
    assert main(["plan", str(write("tiny.yaml", text))]) == 0
    out = capsys.readouterr().out
    assert "verify     8 poses (sphere, listed as v1…) at every calibration setpoint and at 30 °C: 24 in all" in out
    assert "accept     max_drift_mg 0.2; simple acceptance (no decision_rule stated); a partial campaign fails" in out
    assert "warning    2 calibration setpoints cannot fix a degree-2 polynomial: the fit will use degree 1" in out
    assert len([line for line in out.splitlines() if re.match(r"^\s+v[1-8]\s+-?\d", line)]) == 8


@pytest.mark.parametrize("change, where", [
    ("schedule: {kind: six-position}", "syntax"),                          # broken YAML
    ("soak: {", "syntax"),
])
def test_rig_plan_bad_yaml_is_one_line(write, capsys, change: str, where: str) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("schedule: {kind: six-position}", "schedule: {kind: six")
                 if change.startswith("schedule") else TINY_PROCEDURE.replace("soak: {", "soak: {{"))
    err = one_line_error(capsys, ["plan", str(path)], 2)
    assert f"{path}:" in err and where in err


@pytest.mark.parametrize("text, expected", [
    (TINY_PROCEDURE + "colour: blue\n", ":7: colour: unknown key (known here: name, "),   # unknown key
    (TINY_PROCEDURE.replace("settle_s: 1", "settle_s: soon"), ":6: acquisition.settle_s:"),  # wrong type
    (TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [300]"), ":3: setpoints_c[0]: 300 °C is outside"),
])
def test_rig_plan_config_errors_name_file_line_and_key(write, capsys, text: str, expected: str) -> None:
    path = write("tiny.yaml", text)
    err = one_line_error(capsys, ["plan", str(path)], 2)
    assert f"{path}{expected}" in err


def test_rig_export_writes_each_format(fitted_paper_campaign: tuple[Path, Path], tmp_path: Path, capsys) -> None:
    calibration = fitted_paper_campaign[1]
    for fmt, name in (("json", "cal.json"), ("csv", "cal.csv"), ("c-header", "cal.h")):
        assert main(["export", str(calibration), "--format", fmt, "-o", str(tmp_path / name)]) == 0
        assert capsys.readouterr().out.strip() == f"{fmt} of 4 sensors → {tmp_path / name}"
    assert json.loads((tmp_path / "cal.json").read_text())["format"] == "accelcal-rig calibration"
    assert (tmp_path / "cal.csv").read_text().count("\n") == 1 + 4 * 12
    assert "accelcal_apply(" in (tmp_path / "cal.h").read_text()
    assert main(["export", str(calibration), "--format", "csv"]) == 0  # standard output
    assert capsys.readouterr().out.startswith("serial,channel,model,unit,range,parameter,")


def test_rig_export_of_a_broken_calibration_is_one_line(tmp_path: Path, capsys) -> None:
    broken = tmp_path / "cal.yaml"
    broken.write_text("format: accelcal-rig calibration\nformat_version: 7\n")
    err = one_line_error(capsys, ["export", str(broken), "--format", "json"], 2)
    assert f"{broken}:2: format_version: calibration format version 7 is not supported" in err
    assert err.strip().endswith("(and 4 more problems)")  # created, software_version, source, sensors


def test_on_a_terminal_a_live_status_line_shows_progress(tmp_path: Path) -> None:
    import os
    import pty

    controller, terminal = pty.openpty()
    beside_python = Path(sys.executable).parent / "rig"
    process = subprocess.Popen([str(beside_python), "run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run",
                                "-o", "q.h5"], cwd=tmp_path, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=terminal, env={**os.environ, "COLUMNS": "200"})
    os.close(terminal)
    seen = b""
    while True:
        try:
            chunk = os.read(controller, 65536)
        except OSError:  # the terminal closed: the process has exited
            break
        if not chunk:
            break
        seen += chunk
    os.close(controller)
    assert process.wait(timeout=60) == 0
    text = seen.decode()
    assert re.search(r"\r\x1b\[KT15 \(1/2\) (ramp|soak) \d:\d\d:\d\d · .*pose 0/12 · \d:\d\d:\d\d left", text)
    assert re.search(r"\r\x1b\[K\[\d:\d\d:\d\d\] T15: stable after", text)  # messages above the line
    assert "progress: " not in text  # the status line replaces the progress lines on a terminal
    assert text.endswith("\r\x1b[K")  # cleared at the end, the summary follows on stdout


def test_commands_against_a_running_campaign_are_refused_and_change_nothing(tmp_path: Path, capsys) -> None:
    """What a lab types at the wrong file while a campaign runs: --overwrite, --resume, resume, repair, fit."""
    import time

    from accelcal_rig.store.journal import read_journal
    from accelcal_rig.store.paths import journal_path, log_path

    procedure, campaign = tmp_path / "long.yaml", tmp_path / "c.h5"
    procedure.write_text(TINY_PROCEDURE.replace("rig: sim.yaml", f"rig: {REPO / 'configs' / 'sim.yaml'}")
                         .replace("[30]", "{from_c: -40, to_c: 59, step_c: 1}"))  # a run of some seconds
    beside_python = Path(sys.executable).parent / "rig"
    process = subprocess.Popen([str(beside_python), "run", str(procedure), "--dry-run", "-o", str(campaign), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        # the log is written from the campaign's first progress on, just after its journal appears
        while not (journal_path(campaign).exists() and log_path(campaign).exists()) and time.monotonic() < deadline:
            time.sleep(0.005)
        for argv in (["run", str(procedure), "--dry-run", "-o", str(campaign), "--overwrite"],
                     ["run", str(procedure), "--dry-run", "-o", str(campaign), "--resume"],
                     ["resume", str(campaign)], ["repair", str(campaign)],
                     ["fit", str(campaign), "-o", str(tmp_path / "other.yaml")]):
            assert process.poll() is None, "the campaign ended before the commands were tried"
            records = [(r.offset, r.size) for r in read_journal(journal_path(campaign)).records]
            stored = journal_path(campaign).read_bytes()
            log = log_path(campaign).read_bytes()
            err = one_line_error(capsys, argv, 2)
            assert f"pid {process.pid} on " in err, (argv, err)
            now = journal_path(campaign).read_bytes()
            assert all(now[o:o + n] == stored[o:o + n] for o, n in records), argv   # only ever appended to
            assert log_path(campaign).read_bytes().startswith(log), argv           # the log not cut
    finally:
        assert process.wait(timeout=120) == 0
    from accelcal_rig.store.read import campaign_status

    status = campaign_status(campaign)
    assert (status["state"], status["poses_done"], status["campaign_file"]) == ("done", 600, "current")
    assert not (tmp_path / "other.yaml").exists()


def test_resume_finds_the_procedure_from_any_folder(tmp_path: Path) -> None:
    """The campaign stores its procedure's path absolute: resumed from another folder, it is found."""
    (tmp_path / "configs").mkdir()
    shutil.copy(REPO / "configs" / "sim.yaml", tmp_path / "configs" / "sim.yaml")
    (tmp_path / "procedures").mkdir()
    shutil.copy(REPO / "procedures" / "quick-6pos.yaml", tmp_path / "procedures" / "quick.yaml")
    run = rig("run", "procedures/quick.yaml", "--dry-run", "-o", "c.h5", "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    import h5py

    with h5py.File(tmp_path / "c.h5", "r") as f:
        assert f.attrs["procedure_path"] == str(tmp_path / "procedures" / "quick.yaml")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    resumed = rig("resume", str(tmp_path / "c.h5"), cwd=elsewhere)
    assert resumed.returncode == 0 and "the campaign is complete: every pose is stored" in resumed.stdout, resumed.stderr
