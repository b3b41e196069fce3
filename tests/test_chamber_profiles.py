"""`--chamber-profile`: a dry run (and `rig sim`) with the rig's chamber swapped for any built-in profile's
simulated controller — quick-6pos runs with each."""

from __future__ import annotations

import json
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES
from accelcal_rig.protocols.chamber_registers import PROFILES
from accelcal_rig.store.read import load_campaign
from tests.conftest import REPO, SIM_RIG

QUICK = REPO / "procedures" / "quick-6pos.yaml"
IDENTITY = {"watlow-f4": "scaled-int16 controller (model 5270", "watlow-f4t": "float32 controller",
            **{name: f"simulated {name} (PV" for name in LINE_PROFILES},
            "espec-p300": "T,T,accelcal-rig simulated espec-p300,",  # TYPE?: sensors, controller, max temperature
            "watlow-f4t-scpi": "Watlow Electric,accelcal-rig simulated watlow-f4t-scpi,1,"}  # *IDN?: maker, part, serial


@pytest.mark.parametrize("profile", sorted({*PROFILES, *LINE_PROFILES}))
def test_quick_6pos_dry_runs_with_each_chamber_profile(profile: str, tmp_path: Path, capsys) -> None:
    campaign = tmp_path / "quick.h5"
    assert main(["run", str(QUICK), "--dry-run", "--chamber-profile", profile, "-o", str(campaign), "-q",
                 "--no-pdf"]) == 0
    stored = load_campaign(campaign)
    assert stored.state == "done" and len(stored.poses) == stored.poses_planned
    assert stored.attrs["chamber_profile"] == profile
    assert any(e.kind == "preflight" and IDENTITY[profile] in e.message for e in stored.events)


def test_a_resumed_run_keeps_its_swapped_chamber(tmp_path: Path, capsys) -> None:
    campaign = tmp_path / "quick.h5"
    assert main(["run", str(QUICK), "--dry-run", "--chamber-profile", "watlow-f4", "-o", str(campaign), "-q",
                 "--no-pdf", "--faults", "turntable_stall_after_min=60"]) == 1  # stops part-way
    capsys.readouterr()
    assert main(["resume", str(campaign), "-q", "--no-pdf"]) == 0
    stored = load_campaign(campaign)
    assert stored.state == "done" and stored.run_count == 2


def test_run_resume_without_the_flag_continues_with_the_campaigns_chamber(tmp_path: Path, capsys) -> None:
    campaign = tmp_path / "quick.h5"
    common = [str(QUICK), "--dry-run", "-o", str(campaign), "-q", "--no-pdf"]
    assert main(["run", *common, "--chamber-profile", "watlow-f4", "--faults", "turntable_stall_after_min=60"]) == 1
    capsys.readouterr()
    assert main(["run", *common, "--resume"]) == 0
    assert load_campaign(campaign).state == "done"


def test_a_profile_swap_is_for_simulated_chambers_and_known_profiles(tmp_path: Path, capsys) -> None:
    assert main(["run", str(QUICK), "--chamber-profile", "watlow-f4", "-o", str(tmp_path / "q.h5")]) == 2
    assert "only with --dry-run" in capsys.readouterr().err
    assert main(["run", str(QUICK), "--dry-run", "--chamber-profile", "espec", "-o", str(tmp_path / "q.h5")]) == 2
    assert ("'espec' is not a chamber profile (known: espec-p300, simserv, thermotron-8800, watlow-f4, watlow-f4t, "
            "watlow-f4t-scpi)") in capsys.readouterr().err


def test_rig_sim_serves_a_line_profile_any_client_can_reach(tmp_path: Path) -> None:
    """`rig sim --chamber-profile simserv`: the endpoints line names the controller's TCP port, and a plain
    socket speaking SIMSERV (not the project's driver) reads its temperature there."""
    process = subprocess.Popen([sys.executable, "-m", "accelcal_rig", "sim", str(SIM_RIG), "--chamber-profile",
                                "simserv"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        described = json.loads(process.stdout.readline())  # type: ignore[union-attr]
        chamber = described["chamber"]
        assert chamber["protocol"] == "line" and chamber["profile"] == "simserv"
        with socket.create_connection((chamber["host"], chamber["port"]), timeout=5) as connection:
            connection.sendall(b"11004\xb61\xb61\r")
            reply = b""
            while not reply.endswith(b"\r\n"):
                reply += connection.recv(256)
        status, value = reply.rstrip(b"\r\n").split(b"\xb6")
        assert status == b"1" and abs(float(value) - 23.0) < 1.0
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=20)
