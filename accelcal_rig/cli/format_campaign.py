"""What `rig run`, `rig resume`, `rig check`, `rig sim` and `rig certificate` print about a campaign, its rig and
its DUTs, as lines: a run's summary (from the engine's RunResult), each DUT's verdict, each certificate written."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.core.units import gravity_statement

if TYPE_CHECKING:
    from pathlib import Path

    from accelcal_rig.config.rig import RigConfig
    from accelcal_rig.engine.check import InstrumentCheck
    from accelcal_rig.engine.preparation import PreparedCampaign
    from accelcal_rig.engine.session import RunResult
    from accelcal_rig.report.certificate import Written


def run_summary_lines(prepared: PreparedCampaign, result: RunResult, dry_run: bool) -> list[str]:
    """The summary a finished run prints on stdout: what was measured, where it is, and (unless the fit
    failed, which is said on stderr) the fit, the gravity it assumed, its warnings and each DUT's verdict."""
    summary = result.summary
    setpoints = summary.setpoints_c
    size_mb = result.output.stat().st_size / 1e6 if result.output.is_file() else 0.0
    lines = [f"campaign {summary.state}: {prepared.procedure.model.name}",
             f"  setpoints  {len(setpoints)} ({min(setpoints):g} … {max(setpoints):g} °C)",
             f"  poses      {summary.poses_done} of {summary.poses_total} × {summary.n_duts} DUTs × "
             f"{prepared.procedure.model.acquisition.samples_per_pose} samples",
             f"  duration   {format_duration(summary.virtual_duration_s)} {'virtual' if dry_run else 'clock'}, "
             f"{result.wall_s:.1f} s wall",
             f"  output     {result.output} ({size_mb:.1f} MB)"]
    if summary.fit_failed:
        return lines
    lines.append(f"  fit        {summary.fit or 'none (the procedure measures only: fit.mode none)'}")
    if summary.fit:
        lines.append(f"  gravity    {gravity_statement(prepared.rig.model.gravity_m_s2)}")
    lines += warning_lines(summary.fit_warnings)
    lines += verdict_lines(summary.verdicts)
    return lines


def warning_lines(warnings: Iterable[str]) -> list[str]:
    """The fit's warnings, in the summary's column."""
    return [f"  warning    {warning}" for warning in warnings]


def verdict_lines(verdicts: dict[str, tuple[str, tuple[str, ...]]]) -> list[str]:
    """Each DUT's verdict, with the reasons of a FAIL or a CONDITIONAL (the figures inside their guard band)."""
    return [f"  verdict    {serial} {verdict}" + (f": {'; '.join(reasons)}" if verdict in ("FAIL", "CONDITIONAL") else "")
            for serial, (verdict, reasons) in verdicts.items()]


def certificate_line(written: Written) -> str:
    return f"certificate {written.serial} → {written.html}" + (f", {written.pdf.name}" if written.pdf else "")


def check_names(rig: RigConfig, only: frozenset[str]) -> list[str]:
    """The instruments `rig check` will answer for, in its order: `chamber`, `turntable`, `sensor <serial>`."""
    return [*(name for name in ("chamber", "turntable") if name in only),
            *(f"sensor {sensor.serial}" for sensor in (rig.fixture.sensors if "sensors" in only else []))]


def check_line(instrument: InstrumentCheck, width: int) -> str:
    """`chamber    OK      tcp 10.0.0.7:10001: …` or `turntable  FAILED  turntable (serial …): cannot open …`."""
    return f"{instrument.name:<{width}}  {'OK' if instrument.ok else 'FAILED':<6}  {instrument.text}"


def check_failed_line(rig_name: str, failed: list[str], checked: int) -> str:
    """`rig check`'s summary when an instrument failed: how many, and which."""
    others = "; the others answered as configured" if len(failed) < checked else ""
    return (f"rig: error: rig {rig_name}: {len(failed)} of {checked} instrument{'s' if checked != 1 else ''} failed "
            f"the check ({', '.join(failed)}){others}")


def check_closing_line(rig_name: str, only: frozenset[str] | None) -> str:
    """`rig check`'s last line: every instrument (or those of --only) answered as configured."""
    if only:
        return f"rig {rig_name}: the {' and '.join(sorted(only))} answered as configured (only those checked)"
    return f"rig {rig_name}: every instrument answered as configured"


def sim_stopped_line(rig_path: Path, described: dict[str, Any] | None) -> str:
    """What `rig sim` says as SIGINT or SIGTERM ends it: the simulators it closed (as its first line named
    them), or that none was serving yet."""
    if described is None:
        return f"rig sim: stopped before the simulators of {rig_path} were serving"
    chamber, turntable, sensors = described["chamber"], described["turntable"], described["sensors"]
    return (f"rig sim: stopped (simulators of {rig_path} closed: chamber {chamber['endpoint']}, turntable "
            f"{turntable['device']}, {len(sensors)} sensor bridge{'s' if len(sensors) != 1 else ''})")
