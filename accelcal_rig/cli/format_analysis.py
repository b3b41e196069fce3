"""What `rig analyze` prints: each analysis's results (accelcal_rig.analysis) as a table, or as the one JSON
object `--json` prints."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from accelcal_rig.analysis.cooldown import CooldownResult
    from accelcal_rig.analysis.positions import SizeSummary
    from accelcal_rig.analysis.tilt import TiltRow


def cooldown_json(calibration: Path, results: list[CooldownResult]) -> dict[str, Any]:
    """Each DUT's coefficients and span, the number of records instead of the records."""
    from accelcal_rig.fit.calibration import plain

    return plain({"calibration": str(calibration), "sensors": [
        {k: v for k, v in dataclasses.asdict(r).items() if k not in ("t_s", "before_g", "after_g")}
        | {"records": len(r.t_s)} for r in results]})


def cooldown_lines(campaign: Path, calibration: Path, results: list[CooldownResult], figure: Path | None) -> list[str]:
    lines = [f"{campaign}: free cool-down, temperature coefficient per axis (µg/K) with {calibration}",
             f"{'sensor':14s} {'records':>7s} {'from … to (°C)':>16s} {'before x, y, z':>26s} {'after x, y, z':>26s}"]
    for r in results:
        before = " ".join(f"{v:+8.1f}" for v in r.coefficient_before_ug_per_k)
        after = " ".join(f"{v:+8.2f}" for v in r.coefficient_after_ug_per_k)
        lines.append(f"{r.serial:14s} {len(r.t_s):7d} {r.temperature_c.max():7.1f} … {r.temperature_c.min():5.1f} "
                     f"{before:>26s} {after:>26s}")
        if r.outside_range:
            lines.append(f"  warning: {r.outside_range} records outside the calibrated range: clamped or extrapolated "
                         "as the calibration file says")
    return lines + _figure_line(figure)


def tilt_json(setpoint: float, calibration: Path, outside: list[str], rows: dict[str, list[TiltRow]]) -> dict[str, Any]:
    from accelcal_rig.fit.calibration import plain

    return plain({"setpoint_c": setpoint, "calibration": str(calibration), "outside_range": outside,
                  "rows": [dataclasses.asdict(r) for sensor in rows.values() for r in sensor]})


def tilt_lines(campaign: Path, setpoint: float, calibration: Path, outside: list[str],
               rows: dict[str, list[TiltRow]]) -> list[str]:
    """Every pose's pitch and roll (reference, raw, calibrated, SEOQ), each DUT's worst errors, the DUTs whose
    temperatures the calibration does not cover."""
    from accelcal_rig.analysis.tilt import worst_errors_deg

    lines = [f"{campaign} at {setpoint:g} °C with {calibration}: pitch; roll (degrees), paper Eq. 10",
             f"{'sensor':14s} {'pose':>4s} {'reference':>16s} {'without calibration':>20s} {'after calibration':>20s} "
             f"{'SEOQ (%)':>12s}"]
    for serial, sensor_rows in rows.items():
        for r in sensor_rows:
            lines.append(f"{serial:14s} {r.pose_number:4d} {_pair(r.reference_deg, 2):>16s} {_pair(r.before_deg, 3):>20s} "
                         f"{_pair(r.after_deg, 3):>20s} {_pair(r.seoq_percent, 2):>12s}")
        before, after = worst_errors_deg(sensor_rows)
        lines.append(f"{serial:14s} worst |error|: {before:.3f}° without, {after:.4f}° after calibration")
    return lines + [f"warning: {note}: the calibration was clamped to its range" for note in outside]


def _pair(values: tuple[float, float], digits: int) -> str:
    return f"{values[0]:.{digits}f}; {values[1]:.{digits}f}"


def positions_json(setpoint: float, mode: str, floors: dict[str, float], rows: list[SizeSummary]) -> dict[str, Any]:
    from accelcal_rig.fit.calibration import plain

    return plain({"setpoint_c": setpoint, "mode": mode, "noise_floor_mg": floors,
                  "sizes": [dataclasses.asdict(r) for r in rows]})


def positions_lines(campaign: Path, setpoint: float, mode: str, subsets: int, floors: dict[str, float],
                    rows: list[SizeSummary], figure: Path | None) -> list[str]:
    """Per DUT and subset size: the RMSE of |g| on the poses left out, evenly spread and random subsets."""
    lines = [f"{campaign}: {mode} fits at {setpoint:g} °C, RMSE of |g| on the poses each fit left out (mg); "
             f"{subsets} random subsets per size",
             f"{'sensor':14s} {'positions':>9s} {'before':>8s} {'evenly spread':>14s} {'random median':>14s} "
             f"{'random worst':>13s} {'failed':>7s}"]
    for r in rows:
        lines.append(f"{r.serial:14s} {r.size:9d} {r.before_mg:8.3f} {r.structured_mg:14.4f} {r.random_median_mg:14.4f} "
                     f"{r.random_max_mg:13.4f} {r.failed:7d}")
    lines.append("noise floor (mg): " + ", ".join(f"{k} {v:.4f}" for k, v in floors.items())
                 + "; the full set is scored on its own poses")
    return lines + _figure_line(figure)


def _figure_line(figure: Path | None) -> list[str]:
    return [f"figure → {figure}"] if figure is not None else []
