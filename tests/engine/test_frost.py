"""Frost and condensation in a dry run: the purge switched on the simulated controller's event output, the
dew point from its humidity reading (or the rig's configured value), poses held until the DUTs are above
it, all in the event log; what the chamber cannot do is refused before anything moves."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.cli import main
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE

COLD_THEN_WARM = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [-40, 20]")


def run(procedure: Path, *options: str) -> tuple[int, object]:
    campaign = procedure.with_suffix(".h5")
    code = main(["run", str(procedure), "--dry-run", "-o", str(campaign), "-q", "--no-pdf", *options])
    return code, load_campaign(campaign)


def messages(stored, kind: str) -> list[str]:
    return [e.message for e in stored.events if e.kind == kind]


def test_the_purge_follows_the_threshold_and_poses_wait_for_the_dew_point_margin(write, capsys) -> None:
    procedure = write("frost.yaml", COLD_THEN_WARM + "frost: {purge_below_c: 0, dew_point_margin_c: 3}\n")
    code, stored = run(procedure, "--chamber-profile", "simserv")
    assert code == 0 and stored.state == "done"
    assert messages(stored, "purge") == ["dry-air purge on for T-40 (below 0 °C)",
                                         "dry-air purge off for T20 (at or above 0 °C)"]
    (dry,) = messages(stored, "dew-point")
    assert dry.startswith("T20: coldest DUT") and "% RH at" in dry and dry.endswith("poses may begin")
    order = [e.message for e in stored.events if e.kind in ("purge", "dew-point")]
    assert order.index(dry) < order.index("dry-air purge off for T20 (at or above 0 °C)")  # dry air while warming
    assert any("dew point" in m and "% RH" in m for m in messages(stored, "preflight"))


def test_without_the_purge_a_margin_the_room_air_cannot_give_stops_the_run(write, capsys) -> None:
    """The room's dew point (12 °C) stays within 10 °C of DUTs at 20 °C: the wait times out, one line."""
    procedure = write("humid.yaml", COLD_THEN_WARM + "frost: {dew_point_margin_c: 10, dew_point_timeout_min: 20}\n")
    code, stored = run(procedure, "--chamber-profile", "simserv")
    assert code == 1 and stored.state == "aborted"
    assert "T20: DUTs 10 °C above the chamber's dew point: not reached within 0:20:00" in capsys.readouterr().err
    assert any("waiting" in m for m in messages(stored, "dew-point"))
    assert stored.poses and all(pose.setpoint_c == -40 for pose in stored.poses)  # none on a wet fixture


def test_with_the_purge_held_on_the_dry_air_gives_the_margin(write, capsys) -> None:
    procedure = write("purged.yaml", COLD_THEN_WARM + "frost: {purge_below_c: 30, dew_point_margin_c: 10, "
                                                      "dew_point_timeout_min: 20}\n")
    code, stored = run(procedure, "--chamber-profile", "simserv")
    assert code == 0
    assert messages(stored, "purge")[0] == "dry-air purge on for T-40 (below 30 °C)"
    (dry,) = messages(stored, "dew-point")
    dew_point = float(dry.split("(dew point ")[1].split(" °C")[0])
    assert dew_point < 0.0 and "above the frost point" in dry  # the purge's dry air, not the room's 12 °C
    assert messages(stored, "purge")[-1] == "dry-air purge left ON: switch it off once the chamber is at its safe " \
                                            "setpoint and the fixture is warm"


def test_a_configured_dew_point_stands_in_for_a_controller_without_humidity(write, workdir, capsys) -> None:
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text().replace("chamber:\n", "chamber:\n  dew_point_c: 5\n", 1))
    procedure = write("configured.yaml", COLD_THEN_WARM + "frost: {dew_point_margin_c: 3}\n")
    code, stored = run(procedure)  # the rig's Modbus chamber: no humidity register
    assert code == 0
    assert "chamber: dew point 5.0 °C (configured)" in messages(stored, "preflight")
    assert messages(stored, "dew-point")[0].endswith("above the dew point 5.0 °C (configured): poses may begin")


def test_what_the_chamber_cannot_do_is_refused_before_anything_moves(write, capsys) -> None:
    purge = write("purge.yaml", COLD_THEN_WARM + "frost: {purge_below_c: 0}\n")
    code, stored = run(purge)  # watlow-f4t over Modbus: no purge register in its map
    assert code == 1 and not stored.poses
    assert "the chamber's profile has no purge output" in capsys.readouterr().err
    dew = write("dew.yaml", COLD_THEN_WARM + "frost: {dew_point_margin_c: 3}\n")
    code, stored = run(dew)
    assert code == 1 and not stored.poses
    assert "the controller has no humidity reading: set chamber.dew_point_c in the rig config" in capsys.readouterr().err


def test_a_modbus_map_with_a_purge_register_switches_it(write, workdir, capsys) -> None:
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text().replace("chamber:\n", "chamber:\n  registers: {purge_register: 16600}\n", 1))
    procedure = write("modbus.yaml", COLD_THEN_WARM + "frost: {purge_below_c: 0}\n")
    code, stored = run(procedure)
    assert code == 0 and len(messages(stored, "purge")) == 2


RAMP_UP = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [5, 10, 15, 20]") + (
    "method: ramp\nramp: {rate_c_per_min: 0.5, update_s: 30}\nfit: {temperature_model: joint}\n")


def test_on_a_software_ramp_the_wait_holds_the_ramp_and_it_goes_on_from_there(write, capsys) -> None:
    """A 0.1 °C controller (SIMSERV) on a software ramp: its rounded set points read back as written, and
    during a dew-point wait the ramp keeps moving (held, saturated air would never give the margin): the
    poses come once the air is warm enough, on a ramp that never stepped back."""
    procedure = write("ramp.yaml", RAMP_UP + "frost: {dew_point_margin_c: 6.5, dew_point_timeout_min: 120}\n")
    code, stored = run(procedure, "--chamber-profile", "simserv")
    assert code == 0, capsys.readouterr().err
    waits = messages(stored, "dew-point")
    assert any("waiting" in m for m in waits)  # the room's 12 °C dew point made it wait somewhere
    air_c = np.array([np.mean(pose.chamber_temperature_c) for pose in stored.poses])
    assert len(air_c) == 24 and np.all(np.diff(air_c) > -0.5)
    assert any(m.endswith("poses may begin") for m in waits)
