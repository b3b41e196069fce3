"""The rig's references: a reference past its due date is one warning line from `rig plan` and `rig run` (naming
the file, the line and the key), or a one-line refusal when the rig config says `references_overdue: refuse`;
a bad date, a bad --received and a version written as a number are one line each, naming where."""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path

import pytest

from accelcal_rig.cli import main
from tests.conftest import TINY_PROCEDURE

REFERENCES = """
references:
  turntable_angle: {{certificate: CAL-ANG-17, issuer: Angle Lab, due_date: {due}}}
  temperature: {{certificate: CAL-TEMP-112, issuer: Temperature Lab, due_date: 2999-12-31}}
references_overdue: {policy}
"""


def _rig(workdir: Path, due: str, policy: str = "warn") -> Path:
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text() + REFERENCES.format(due=due, policy=policy))
    return rig


def _line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def _on(day: dt.date):
    return lambda: day


def test_plan_warns_of_an_overdue_reference_in_one_line(write, workdir: Path, capsys) -> None:
    rig = _rig(workdir, "2030-06-30")
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    assert main(["plan", str(procedure)], today=_on(dt.date(2030, 6, 30))) == 0  # due today: still in calibration
    assert capsys.readouterr().err == ""
    assert main(["plan", str(procedure)], today=_on(dt.date(2030, 7, 1))) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [f"rig: warning: {rig}:{_line_of(rig, 'turntable_angle:')}: references.turntable_angle.due_date: "
                   "overdue since 2030-06-30 (certificate CAL-ANG-17 by Angle Lab): a campaign with it is not "
                   "traceable through its turntable angle"]


def test_run_warns_and_runs(write, workdir: Path, capsys) -> None:
    _rig(workdir, "2030-06-30")
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    code = main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5"), "-q", "--no-pdf"],
                today=_on(dt.date(2031, 1, 1)))
    warnings = [line for line in capsys.readouterr().err.splitlines() if "references." in line]
    assert code == 0 and (workdir / "c.h5").exists()
    assert len(warnings) == 1 and "references.turntable_angle.due_date: overdue since 2030-06-30" in warnings[0]


@pytest.mark.parametrize("command", ["plan", "run"])
def test_an_overdue_reference_is_refused_when_the_rig_config_says_so(write, workdir: Path, capsys,
                                                                     command: str) -> None:
    rig = _rig(workdir, "2030-06-30", "refuse")
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    output = workdir / "c.h5"
    argv = [command, str(procedure)] + (["--dry-run", "-o", str(output), "-q"] if command == "run" else [])
    assert main(argv, today=_on(dt.date(2030, 7, 1))) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"rig: error: {rig}:{_line_of(rig, 'turntable_angle:')}: "
                                               "references.turntable_angle.due_date: overdue since 2030-06-30")
    assert "refused (references_overdue: refuse)" in err[0]
    assert not output.exists()  # nothing started
    assert main(argv, today=_on(dt.date(2030, 6, 30))) == 0  # in calibration: runs


def test_a_bad_due_date_names_the_file_line_and_key(write, workdir: Path, capsys) -> None:
    rig = _rig(workdir, "2030-02-30")
    assert main(["plan", str(write("tiny.yaml", TINY_PROCEDURE))]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"rig: error: {rig}:{_line_of(rig, 'turntable_angle:')}: references.turntable_angle.due_date: '2030-02-30' "
        "is not a date: day is out of range for month"]


def test_a_bad_received_date_and_a_numeric_version_are_one_line(write, workdir: Path, capsys) -> None:
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    assert main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5"), "--received", "20.11.2026"]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "rig: error: --received: '20.11.2026' is not a date: write it YYYY-MM-DD"]
    numbered = write("numbered.yaml", TINY_PROCEDURE.replace("name: tiny\n", "name: tiny\nversion: 1.10\n"))
    assert main(["plan", str(numbered)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and re.match(rf"rig: error: {re.escape(str(numbered))}:2: version: write it as quoted text", err[0])


def test_a_receipt_after_the_calibration_is_refused_naming_its_key(write, workdir: Path, capsys) -> None:
    """An item is received before it is calibrated: `--received` or a fixture entry's `received_date` after the
    day of the run is one line naming which, and no campaign is made."""
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    today = _on(dt.date(2026, 12, 1))
    assert main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5"), "--received", "2026-12-02"],
                today=today) == 2
    assert capsys.readouterr().err.splitlines() == [
        "rig: error: --received: 2026-12-02 is after the calibration (2026-12-01): an item is received before it is "
        "calibrated"]
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text().replace("{serial: ADX355-A002, name: dut2,",
                                           "{serial: ADX355-A002, name: dut2, received_date: 2027-01-05,"))
    assert main(["run", str(procedure), "--dry-run", "-o", str(workdir / "c.h5"), "--received", "2026-11-20"],
                today=today) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "fixture.sensors[1].received_date (ADX355-A002): 2027-01-05 is after" in err[0]
    assert not (workdir / "c.h5").exists()


def test_serials_that_differ_only_by_case_are_one_item(write, workdir: Path, capsys) -> None:
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text().replace("{serial: ADX355-A002,", "{serial: adx355-a001,"))
    assert main(["plan", str(write("tiny.yaml", TINY_PROCEDURE))]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "distinct, case aside: 'ADX355-A001' and 'adx355-a001'" in err[0]


def test_a_gravity_survey_needs_its_value(write, workdir: Path, capsys) -> None:
    """A survey named as the site gravity's reference with the standard value left in place (the example rig
    config once did this) is refused; stating the surveyed value is enough."""
    rig = workdir / "sim.yaml"
    survey = ("references:\n  site_gravity: {certificate: GRAV-1, issuer: Survey, due_date: 2999-12-31}\n")
    rig.write_text(rig.read_text() + survey)
    procedure = write("tiny.yaml", TINY_PROCEDURE)
    assert main(["plan", str(procedure)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "site_gravity names a gravity survey but gravity_m_s2 is not stated" in err[0]
    rig.write_text(rig.read_text() + "gravity_m_s2: 9.8112\n")
    assert main(["plan", str(procedure)]) == 0


def test_plan_says_what_the_gyroscope_reference_does_with_the_earths_rate(tmp_path: Path, capsys) -> None:
    """A gyroscope campaign on a rig config without latitude_deg: `rig plan` says the Earth's rate stays in the
    fitted bias (as the calibration and the certificate do), in its lines and in --json."""
    import json

    from tests.conftest import REPO

    config = tmp_path / "imu.yaml"
    config.write_text((REPO / "configs" / "sim-imu.yaml").read_text())
    procedure = REPO / "procedures" / "imu-fast.yaml"
    assert main(["plan", str(procedure), "--config", str(config)]) == 0
    assert "earth      taken out at latitude 48.14°" in capsys.readouterr().out
    lines = config.read_text().splitlines()
    config.write_text("\n".join(line for line in lines if not line.startswith(("latitude_deg:", "heading_deg:"))))
    assert main(["plan", str(procedure), "--config", str(config), "--json"]) == 0
    stated = json.loads(capsys.readouterr().out)["earth_rate"]
    assert "is NOT taken out: the rig config states no latitude_deg" in stated
