"""The registry's verdicts: PASS, FAIL, CONDITIONAL (a limit met or missed inside its guard band) and NOT JUDGED
(stored as none). Migration 0005 widens the column CONDITIONAL did not fit, keeping the records; `list --verdict`
takes all four, `list` marks and filters dry runs against real calibrations, and `stats` counts CONDITIONAL as
judged, neither passed nor failed, and says so."""

from __future__ import annotations

import json
from datetime import timedelta
from pathlib import Path

import pytest
import sqlalchemy as sa

from accelcal_rig.cli import main
from accelcal_rig.registry.database import Registry, _engine
from accelcal_rig.registry.entries import campaign_entries
from accelcal_rig.registry.location import normalised

#: Each calibration's verdict, as real (not dry-run) calibrations of one lot.
VERDICTS = {"V-PASS": "PASS", "V-FAIL": "FAIL", "V-COND": "CONDITIONAL", "V-NONE": None}


def _lot(quick_campaign: tuple[Path, Path]) -> list[dict]:
    """One calibration per verdict, each its own serial, as a real rig's; and the dry run's four."""
    campaign, calibration = quick_campaign
    dry = campaign_entries(campaign, calibration)
    real = [dry[0] | {"serial": serial, "verdict": verdict, "simulated": False, "fit_sha256": f"{k:064d}",
                      "calibrated_at": dry[0]["calibrated_at"] + timedelta(days=k),
                      "verdict_reasons": ["no acceptance limits stated"] if verdict is None
                      else [f"bias x at 25 °C against its limit: {verdict}"]}
            for k, (serial, verdict) in enumerate(VERDICTS.items(), start=1)]
    return real + dry


def test_a_0004_database_upgrades_to_hold_a_conditional_verdict(registry_url: str, quick_campaign) -> None:
    registry = Registry(_engine(registry_url), registry_url)
    registry.upgrade("0004")
    table = sa.Table("calibrations", sa.MetaData(), autoload_with=registry.engine)
    entries = _lot(quick_campaign)
    before = [e for e in entries if e["verdict"] != "CONDITIONAL"]
    with registry.engine.begin() as connection:
        connection.execute(table.insert(), [{k: v for k, v in e.items() if k in table.c} for e in before])
    if registry.engine.dialect.name == "postgresql":  # SQLite does not hold a VARCHAR to its length
        conditional = next(e for e in entries if e["verdict"] == "CONDITIONAL")
        with pytest.raises(sa.exc.DataError), registry.engine.begin() as connection:
            connection.execute(table.insert(), [{k: v for k, v in conditional.items() if k in table.c}])
    upgraded = Registry.open(registry_url)
    width = {c["name"]: c["type"] for c in sa.inspect(upgraded.engine).get_columns("calibrations")}["verdict"]
    assert width.length == 16
    kept = {r["serial"]: r["verdict"] for r in upgraded.calibrations()}
    assert kept == {e["serial"]: e["verdict"] for e in before}  # every record, its verdict as it was
    added, _ = upgraded.add(entries)
    assert len(added) == 1 and upgraded.calibration(added[0])["verdict"] == "CONDITIONAL"


def test_list_by_verdict_and_by_how_it_was_made(registry_url: str, quick_campaign) -> None:
    registry = Registry.open(registry_url)
    entries = _lot(quick_campaign)
    registry.add(entries)
    for verdict in ("PASS", "FAIL", "CONDITIONAL"):
        expected = sorted(e["serial"] for e in entries if e["verdict"] == verdict)
        assert sorted(r["serial"] for r in registry.calibrations(verdict=verdict)) == expected
    unjudged = sorted(e["serial"] for e in entries if e["verdict"] is None)
    assert sorted(r["serial"] for r in registry.calibrations(verdict="NOT JUDGED")) == unjudged
    assert {r["serial"] for r in registry.calibrations(simulated=False)} == set(VERDICTS)
    assert sorted(r["serial"] for r in registry.calibrations(simulated=True)) == sorted(
        e["serial"] for e in entries if e["simulated"])


def test_the_command_line_lists_marks_and_counts_them(tmp_path: Path, quick_campaign, capsys) -> None:
    url = normalised(str(tmp_path / "lab.sqlite"))
    entries = _lot(quick_campaign)
    Registry.open(url).add(entries)
    assert main(["registry", "list", "--verdict", "NOT JUDGED", "--real", "--registry", url]) == 0
    lines = capsys.readouterr().out.splitlines()
    header = lines[0].split()
    assert header[header.index("verdict") + 1] == "made" and len(lines) == 2
    assert lines[1].split()[1] == "V-NONE" and "NOT JUDGED real" in " ".join(lines[1].split())
    assert main(["registry", "list", "--simulated", "--json", "--registry", url]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert len(listed) == sum(e["simulated"] for e in entries) and all(r["simulated"] for r in listed)
    assert main(["registry", "list", "--verdict", "CONDITIONAL", "--registry", url]) == 0
    rows = capsys.readouterr().out.splitlines()[1:]
    assert [r.split()[1] for r in rows] == ["V-COND"] and "CONDITIONAL real" in " ".join(rows[0].split())
    assert main(["registry", "stats", "--part", "adxl355", "--json", "--registry", url]) == 0
    stats = json.loads(capsys.readouterr().out)["channels"]["accel"]
    judged = [v for v in VERDICTS.values() if v is not None]
    assert (stats["judged"], stats["passed"], stats["conditional"], stats["failed"]) == (
        len(judged), judged.count("PASS"), judged.count("CONDITIONAL"), judged.count("FAIL"))
    assert stats["yield"] == pytest.approx(judged.count("PASS") / len(judged))
    assert main(["registry", "stats", "--part", "adxl355", "--registry", url]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert (f"{judged.count('PASS')} of {len(judged)} judged passed" in first
            and f"{judged.count('CONDITIONAL')} conditional (inside a guard band: neither passed nor failed)" in first)


def test_a_verdict_the_registry_does_not_know_is_refused_in_one_line(tmp_path: Path, capsys) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["registry", "list", "--verdict", "MAYBE", "--registry", str(tmp_path / "lab.sqlite")])
    err = capsys.readouterr().err.strip()
    assert exit_.value.code == 2 and len(err.splitlines()) == 1 and "--verdict" in err and "CONDITIONAL" in err
