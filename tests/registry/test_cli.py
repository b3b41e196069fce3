"""`rig registry …` and the automatic recording of `rig run`, `rig fit` and `rig fit-recording`, as an operator
uses them: which registry (flag, rig config, environment, default), idempotent adds, and one-line errors."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from accelcal_rig.cli.outcome import EXIT_NOT_RECORDED
from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from tests.conftest import REPO


def rig(*argv: str) -> int:
    return main([str(a) for a in argv])


def test_rig_run_records_every_dut_and_add_is_idempotent(tmp_path: Path, capsys) -> None:
    registry = tmp_path / "lab.sqlite"
    campaign = tmp_path / "quick.h5"
    assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
               "--registry", registry) == 0
    assert f"registry   4 calibrations recorded in sqlite:///{registry.resolve()}" in capsys.readouterr().out
    assert rig("registry", "add", campaign, "--registry", registry) == 0
    assert capsys.readouterr().out.strip() == f"{campaign}: 0 added, 4 registered already"
    assert Registry.open(normalised(str(registry))).count() == 4


def test_list_show_trend_stats_and_export(tmp_path: Path, capsys) -> None:
    registry = tmp_path / "lab.sqlite"
    campaign = tmp_path / "quick.h5"
    rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
        "--registry", registry)
    # A refit with other options of the same campaign is another calibration of the same sensors.
    assert rig("fit", campaign, "-o", tmp_path / "refit.yaml", "--parameters", "bias-scale", "--registry", registry) == 0
    capsys.readouterr()
    assert rig("registry", "list", "--serial", "ADX355-A002", "--json", "--registry", registry) == 0
    listed = json.loads(capsys.readouterr().out)
    assert len(listed) == 2 and all(r["serial"] == "ADX355-A002" and r["part"] == "adxl355" for r in listed)
    assert all(r["calibrated_at"].endswith("Z") and "calibration" not in r for r in listed)
    assert rig("registry", "show", "ADX355-A002", "--registry", registry) == 0
    shown = capsys.readouterr().out  # dry runs are rehearsals: no valid calibration unless asked for
    assert shown.startswith("ADX355-A002: no valid calibration (only dry runs (simulated) are recorded")
    assert rig("registry", "show", "ADX355-A002", "--simulated", "--registry", registry) == 0
    shown = capsys.readouterr().out
    assert shown.startswith("ADX355-A002 (adxl355): valid calibration") and "(SIMULATED: a dry run)" in shown
    assert "history (2):" in shown
    assert rig("registry", "trend", "ADX355-A002", "--json", "--simulated", "--registry", registry) == 0
    assert len(json.loads(capsys.readouterr().out)["channels"]["accel"]["calibrations"]) == 2
    assert rig("registry", "stats", "--part", "adxl355", "--json", "--simulated", "--registry", registry) == 0
    stats = json.loads(capsys.readouterr().out)["channels"]["accel"]
    assert stats["sensors"] == 4 and stats["calibrations"] == 8
    header = tmp_path / "accel.h"
    assert rig("registry", "export", "ADX355-A002", "--format", "c-header", "-o", header, "--registry", registry) == 2
    assert "no valid calibration in the registry (dry runs are left out" in capsys.readouterr().err
    assert rig("registry", "export", "ADX355-A002", "--format", "c-header", "-o", header, "--simulated",
               "--registry", registry) == 0
    assert "ADX355-A002" in header.read_text() and "accelcal_apply" in header.read_text()
    capsys.readouterr()
    params = tmp_path / "px4.params"
    assert rig("registry", "export", "ADX355-A002", "--format", "px4-params", "--device-id", "1310988",
               "-o", params, "--simulated", "--registry", registry) == 0
    assert "TC_A0_X0_0" in params.read_text() and "TC_A0_ID\t1310988" in params.read_text()
    assert "rig: warning:" in capsys.readouterr().err  # what PX4 cannot hold (scale, cross-axis) is said


def test_which_registry_flag_rig_config_environment_and_dry_runs_apart(tmp_path: Path, capsys, monkeypatch) -> None:
    procedure_dir = tmp_path / "lab"
    procedure_dir.mkdir()
    shutil.copy(REPO / "configs" / "sim.yaml", procedure_dir / "sim.yaml")
    (procedure_dir / "sim.yaml").write_text((procedure_dir / "sim.yaml").read_text() + "\nregistry: rig-registry.sqlite\n")
    procedure = procedure_dir / "quick.yaml"
    procedure.write_text((REPO / "procedures" / "quick-6pos.yaml").read_text().replace("../configs/sim.yaml", "sim.yaml"))
    monkeypatch.setenv("ACCELCAL_DRY_RUN_REGISTRY", str(tmp_path / "dry-runs.sqlite"))
    assert rig("run", procedure, "--dry-run", "-o", tmp_path / "a.h5", "-q", "--no-pdf") == 0
    assert "(a dry run: kept apart from the lab's registry)" in capsys.readouterr().out
    # A dry run is no calibration of the lab's: not in the rig config's registry, nor the environment's.
    assert not (procedure_dir / "rig-registry.sqlite").exists()
    assert Registry.open(normalised(str(tmp_path / "dry-runs.sqlite"))).count() == 4
    assert rig("run", procedure, "--dry-run", "-o", tmp_path / "b.h5", "-q", "--no-pdf", "--registry",
               tmp_path / "flag.sqlite") == 0
    assert Registry.open(normalised(str(tmp_path / "flag.sqlite"))).count() == 4  # the flag over all
    capsys.readouterr()
    # Told to, `add` records a dry run in the registry --config names (relative to the rig config).
    assert rig("registry", "add", tmp_path / "a.h5", "--config", procedure_dir / "sim.yaml") == 0
    assert capsys.readouterr().out.strip() == f"{tmp_path / 'a.h5'}: 4 added"
    monkeypatch.setenv("ACCELCAL_REGISTRY", str(tmp_path / "environment.sqlite"))
    assert rig("registry", "list", "--json") == 0  # no flag, no config: the environment's
    assert json.loads(capsys.readouterr().out) == [] and not (tmp_path / "environment.sqlite").exists()  # read only
    assert rig("registry", "list") == 0  # an empty lab registry says where dry runs went
    assert f"dry runs are recorded apart, in sqlite:///{tmp_path / 'dry-runs.sqlite'}" in capsys.readouterr().out
    assert rig("registry", "list", "--config", procedure_dir / "sim.yaml", "--json") == 0
    assert len(json.loads(capsys.readouterr().out)) == 4


def test_a_dry_run_without_a_registry_named_goes_to_the_dry_runs_default(tmp_path: Path, capsys, monkeypatch) -> None:
    """Neither flag nor ACCELCAL_DRY_RUN_REGISTRY: dry-runs.sqlite beside the default registry, not the lab's
    (the environment's); `rig registry add` of a dry run's campaign goes there too."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.delenv("ACCELCAL_DRY_RUN_REGISTRY")
    monkeypatch.setenv("ACCELCAL_REGISTRY", str(tmp_path / "lab.sqlite"))
    campaign = tmp_path / "quick.h5"
    assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf") == 0
    default = tmp_path / "data" / "accelcal-rig" / "dry-runs.sqlite"
    assert f"recorded in sqlite:///{default}" in capsys.readouterr().out
    assert Registry.open(normalised(str(default))).count() == 4 and not (tmp_path / "lab.sqlite").exists()
    assert rig("registry", "add", campaign) == 0
    assert capsys.readouterr().out.strip() == (f"{campaign}: 0 added, 4 registered already (a dry run: in "
                                               f"sqlite:///{default}, apart from the lab's registry)")
    assert not (tmp_path / "lab.sqlite").exists()


def test_hand_held_fits_are_recorded_with_their_part(tmp_path: Path, capsys) -> None:
    """The real recording of tests/data (imucal's published hand-turned IMU session)."""
    registry = tmp_path / "lab.sqlite"
    recording = REPO / "tests" / "data" / "real" / "imucal-annotated-session.csv"
    code = rig("fit-recording", recording, "--columns", "samples,acc_x,acc_y,acc_z", "--time-unit", "samples",
               "--rate-hz", "204.8", "--units", "counts", "--counts-per-g", "2048", "--parameters", "bias-scale",
               "-o", tmp_path / "hand.yaml", "--part", "imucal-imu", "--registry", registry, "--json")
    assert code == 0, capsys.readouterr().err
    rows = Registry.open(normalised(str(registry))).calibrations()
    assert len(rows) == 1 and rows[0]["part"] == "imucal-imu" and rows[0]["source_kind"] == "recording"
    assert rows[0]["procedure"] == "hand-held" and rows[0]["source_path"] == str(recording.resolve())


@pytest.mark.parametrize(("argv", "message"), [
    (["registry", "show", "NOBODY"], "serial NOBODY: no calibration in the registry"),
    (["registry", "list", "--since", "yesterday"], "--since 'yesterday': not a date (YYYY-MM-DD)"),
    (["registry", "stats", "--part", "nothing"], "part nothing: no calibration in the registry (dry runs are left "
                                                 "out: --simulated includes them)"),
    (["registry", "list", "--registry", "mysql://lab/x"], "registry 'mysql://lab/x': not an SQLite path or file, nor a "
                                                          "postgresql:// URL"),
])
def test_bad_requests_are_one_line(argv: list[str], message: str, tmp_path: Path, capsys) -> None:
    if "--registry" not in argv:
        Registry.open(normalised(str(tmp_path / "empty.sqlite")))  # made, with nothing in it
        argv = [*argv, "--registry", str(tmp_path / "empty.sqlite")]
    assert rig(*argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(message) and len(err.splitlines()) == 1


@pytest.mark.parametrize(("damage", "message"), [
    ("UPDATE calibrations SET calibrated_at = 'last tuesday'", "cannot be read (Invalid isoformat string: 'last "
                                                               "tuesday'): the database was damaged or changed by hand"),
    ("DROP TABLE users", "table users is missing: the database was damaged or changed by hand"),
    (None, "file is not a database"),
])
def test_a_damaged_registry_is_one_line_and_exit_2(damage: str | None, message: str, tmp_path: Path, capsys) -> None:
    import sqlite3

    path = tmp_path / "registry.sqlite"
    if damage is None:
        path.write_bytes(b"x" * 4096)
    else:
        campaign = tmp_path / "quick.h5"
        assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
                   "--registry", path) == 0
        with sqlite3.connect(path) as connection:
            connection.execute(damage)
    capsys.readouterr()
    for argv in (["list"], ["show", "ADX355-A001"], ["stats", "--part", "adxl355", "--simulated"]):
        assert rig("registry", *argv, "--registry", path) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err == f"rig: error: registry sqlite:///{path}: {message}", argv


def test_a_reader_of_a_registry_not_made_yet_says_so_and_makes_none(tmp_path: Path, capsys) -> None:
    missing = tmp_path / "lab" / "registry.sqlite"
    assert rig("registry", "show", "ANY", "--registry", missing) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"rig: error: registry sqlite:///{missing}: does not exist (nothing recorded in it yet)"
    assert rig("registry", "list", "--registry", missing, "--json") == 0
    assert json.loads(capsys.readouterr().out) == [] and not missing.parent.exists()


def test_a_registry_that_cannot_take_the_record_loses_nothing(tmp_path: Path, capsys) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("")
    campaign = tmp_path / "quick.h5"
    assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
               "--registry", blocked / "lab.sqlite") == EXIT_NOT_RECORDED  # the campaign and its calibration stand
    err = capsys.readouterr().err
    assert "rig: warning: not recorded in the registry:" in err and f"rig resume {campaign} will record them" in err
    assert campaign.with_suffix(".calibration.yaml").is_file()
    blocked.unlink()                                   # the registry can take them now: resume records them
    assert rig("resume", campaign, "--registry", blocked / "lab.sqlite", "-q", "--no-pdf") == 0
    assert "4 calibrations recorded" in capsys.readouterr().out


def test_a_trend_of_fits_without_stated_uncertainty_is_printed_not_a_crash(tmp_path: Path, capsys) -> None:
    """Hand-held fits state no uncertainty: the drift is given without one, on the command line and the page."""
    from starlette.testclient import TestClient

    from accelcal_rig.fit.calibration import load_calibration
    from accelcal_rig.registry.entries import recording_entries
    from accelcal_rig.web.app import create_app

    registry = normalised(str(tmp_path / "lab.sqlite"))
    recording = REPO / "tests" / "data" / "real" / "imucal-annotated-session.csv"
    assert rig("fit-recording", recording, "--columns", "samples,acc_x,acc_y,acc_z", "--time-unit", "samples",
               "--rate-hz", "204.8", "--units", "counts", "--counts-per-g", "2048", "--parameters", "bias-scale",
               "-o", tmp_path / "hand.yaml", "--registry", registry) == 0
    first = Registry.open(registry).calibrations()[0]
    later = recording_entries(recording, load_calibration(tmp_path / "hand.yaml"), "unknown")[0]
    from datetime import timedelta

    Registry.open(registry).add([shifted(later, 1.0) | {"fit_sha256": "f" * 64, "calibrated_at": first["calibrated_at"]
                                                        + timedelta(days=100)}])
    capsys.readouterr()
    serial = first["serial"]
    assert rig("registry", "trend", serial, "--registry", registry) == 0
    assert "(uncertainty not stated) mg" in capsys.readouterr().out
    page = TestClient(base_url="http://127.0.0.1", app=create_app([tmp_path], registry)).get(
        f"/registry/serials/{serial}")
    assert page.status_code == 200 and "uncertainty not stated" in page.text


def test_a_trend_of_calibrations_minutes_apart_states_no_drift(tmp_path: Path, quick_campaign, capsys) -> None:
    """A second calibration 12 minutes after the first: the two are listed, the drift per year is not stated,
    in one line, and the command succeeds; asked for a shorter span it is stated."""
    from datetime import timedelta

    from accelcal_rig.registry.entries import campaign_entries

    registry = normalised(str(tmp_path / "lab.sqlite"))
    first = campaign_entries(*quick_campaign)[0] | {"simulated": False}
    later = shifted(first, 0.5) | {"fit_sha256": "e" * 64, "calibrated_at": first["calibrated_at"] + timedelta(minutes=12)}
    Registry.open(registry).add([first, later])
    assert rig("registry", "trend", first["serial"], "--registry", registry) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 4 and out[-1] == ("  drift per year: not stated: the calibrations span 12 minutes, under the "
                                         "30 days a drift per year needs (--min-span-days sets it)")
    assert rig("registry", "trend", first["serial"], "--min-span-days", "0.001", "--json", "--registry", registry) == 0
    drift = json.loads(capsys.readouterr().out)["channels"]["accel"]["drift_per_year"]["bias"]["axes"]
    minutes_per_year = 365.25 * 1440
    assert drift[0]["per_year"] == pytest.approx(0.5 * minutes_per_year / 12)


def test_a_hand_held_fit_of_a_dry_runs_campaign_is_a_dry_run_too(tmp_path: Path, quick_campaign, capsys,
                                                                  monkeypatch) -> None:
    monkeypatch.setenv("ACCELCAL_DRY_RUN_REGISTRY", str(tmp_path / "dry-runs.sqlite"))
    monkeypatch.setenv("ACCELCAL_REGISTRY", str(tmp_path / "lab.sqlite"))
    campaign, _ = quick_campaign
    assert rig("fit-recording", campaign, "--setpoint", "15", "--parameters", "bias-scale", "-o", tmp_path / "hand.yaml") == 0
    assert "(a dry run: kept apart from the lab's registry)" in capsys.readouterr().out
    rows = Registry.open(normalised(str(tmp_path / "dry-runs.sqlite"))).calibrations()
    assert [(r["source_kind"], r["simulated"]) for r in rows] == [("recording", True)]
    assert not (tmp_path / "lab.sqlite").exists()


def shifted(entry: dict, by: float) -> dict:
    """A registry entry whose bias figure is `by` more on every axis (a later calibration of the same sensor)."""
    figures = [f | {"value": [v + by for v in f["value"]]} if f["name"] == "bias" else f for f in entry["figures"]]
    return entry | {"figures": figures}


def test_a_registry_named_by_the_environment_is_the_one_a_resume_records_in(tmp_path: Path, capsys,
                                                                            monkeypatch) -> None:
    """The dry runs' registry named only by $ACCELCAL_DRY_RUN_REGISTRY, and unable to take the rows at the end of
    the run: a resume from another shell (another environment) records them there, not in its own default."""
    blocked = tmp_path / "blocked"
    blocked.write_text("")
    named = blocked / "named.sqlite"
    monkeypatch.setenv("ACCELCAL_DRY_RUN_REGISTRY", str(named))
    campaign = tmp_path / "quick.h5"
    assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
               "--no-publish") == EXIT_NOT_RECORDED
    blocked.unlink()
    elsewhere = tmp_path / "elsewhere.sqlite"
    monkeypatch.setenv("ACCELCAL_DRY_RUN_REGISTRY", str(elsewhere))          # another shell's
    capsys.readouterr()
    assert rig("resume", campaign, "-q", "--no-pdf", "--no-publish") == 0
    assert f"4 calibrations recorded in sqlite:///{named}" in capsys.readouterr().out
    assert len(Registry.open(normalised(str(named))).calibrations()) == 4 and not elsewhere.exists()


def test_a_resume_of_a_complete_campaign_ends_its_card_as_its_file_says(tmp_path: Path, capsys) -> None:
    """A run killed after its last pose (or whose last update never reached the registry) left its card
    "running"; resuming the complete campaign publishes how it ended."""
    import sqlalchemy as sa

    from accelcal_rig.registry.live import LiveBoard
    from accelcal_rig.registry.schema import live_campaigns

    registry = normalised(str(tmp_path / "lab.sqlite"))
    campaign = tmp_path / "quick.h5"
    assert rig("run", REPO / "procedures" / "quick-6pos.yaml", "--dry-run", "-o", campaign, "-q", "--no-pdf",
               "--registry", registry) == 0
    board = LiveBoard(Registry.open(registry))
    (card,) = board.campaigns()
    assert card["state"] == "done" and card["poses_done"] == card["poses_total"] > 0
    with board.engine.begin() as connection:                 # what a kill before the last update leaves
        connection.execute(sa.update(live_campaigns).values(state="running", phase="poses", poses_done=0))
    assert rig("resume", campaign, "-q", "--no-pdf", "--registry", registry) == 0
    (card,) = LiveBoard(Registry.open(registry)).campaigns()
    assert card["state"] == "done" and card["poses_done"] == card["poses_total"]
    assert set(card["verdicts"]) == {"ADX355-A001", "ADX355-A002", "ADX355-A003", "ADX355-A004"}   # quick-6pos judges none
