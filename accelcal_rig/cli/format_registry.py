"""`rig registry` as a person reads it: the registry's rows (as `Registry.calibrations` gives them) and its
analyses (`registry.analysis`) as lines, and a row as JSON."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path
from typing import Any


def calibration_table(rows: list[dict[str, Any]], dry_runs: str | None = None) -> list[str]:
    """`rig registry list`: a header and one line per calibration, a dry run's `dry run` in the `made` column (a
    sentence when none match, naming the dry runs' registry `dry_runs` if given: they are recorded there)."""
    if not rows:
        return ["no calibrations match" + (f" (dry runs are recorded apart, in {dry_runs}: --registry names it)"
                                           if dry_runs else "")]
    lines = [f"{'id':>6}  {'serial':<16} {'channel':<7} {'part':<8} {'calibrated (UTC)':<19} {'verdict':<11} "
             f"{'made':<7} {'valid °C':<15} {'procedure':<22} source"]
    for r in rows:
        lines.append(f"{r['id']:>6}  {r['serial']:<16} {_channel(r):<7} {r['part']:<8} {r['calibrated_at']:%Y-%m-%d %H:%M:%S} "
                     f"{r['verdict'] or 'NOT JUDGED':<11} {'dry run' if r['simulated'] else 'real':<7} "
                     f"{r['valid_from_c']:>6.1f}…{r['valid_to_c']:<7.1f} {r['procedure'][:22]:<22} "
                     f"{Path(r['source_path']).name}")
    return lines


def _channel(row: dict[str, Any]) -> str:
    return str(row["channel"])


#: Decimals a figure is shown with, by its unit (others: 3).
_DIGITS = {"ppm": 0, "°/s": 4}


def _digits(unit: str) -> int:
    return _DIGITS.get(unit, 3)


def sensor_lines(serial: str, current: dict[str, dict[str, Any] | None], rows: list[dict[str, Any]],
                 simulated: bool, why: dict[str, str] | None = None) -> list[str]:
    """`rig registry show`: the sensor's valid calibration of each channel (or why it has none), then its
    history; each channel named where the sensor has more than one."""
    labelled = len(current) > 1
    lines = []
    for channel, valid in current.items():
        lines += _current_lines(serial, valid, simulated, f" {channel}" if labelled else "",
                                (why or {}).get(channel, ""))
    lines.append(f"history ({len(rows)}):")
    for r in rows:
        bias = r["figures"].get("bias")
        shown = triple(bias["value"], bias["unit"], digits=_digits(bias["unit"])) if bias else "—"
        lines.append(f"  {r['id']:>6}  {r['calibrated_at']:%Y-%m-%d %H:%M}  {r['verdict'] or 'NOT JUDGED':<10}  "
                     + (f"{_channel(r):<5}  " if labelled else "")
                     + f"bias {shown}  {Path(r['source_path']).name}" + (" (simulated)" if r["simulated"] else ""))
    return lines


def _current_lines(serial: str, current: dict[str, Any] | None, simulated: bool, label: str = "",
                   why: str = "") -> list[str]:
    if current is None:
        return [f"{serial}{label}: no valid calibration ({why or 'its newest calibration failed its acceptance limits'})"]
    dry = " (SIMULATED: a dry run)" if current["simulated"] else ""
    return [f"{serial}{label} ({current['part']}): valid calibration {current['id']}{dry}, "
            f"measured {current['calibrated_at']:%Y-%m-%d} "
            f"by {current['procedure']} on {current['rig']}, {current['valid_from_c']:.1f}…{current['valid_to_c']:.1f} °C, "
            f"verdict {current['verdict'] or 'NOT JUDGED (no acceptance limits stated)'}",
            f"  at {current['reference_c']:g} °C: " + "; ".join(figure_text(f) for f in current["figures"].values()),
            f"  source {current['source_path']} (SHA-256 {current['source_sha256'][:16]}…), software "
            f"{current['software_version']}"]


def figure_text(figure: dict[str, Any]) -> str:
    """`bias +1.234±0.010/… mg`: a registry figure with its values (each ± its expanded uncertainty, where stated)."""
    if figure["axes"]:
        return f"{figure['label']} {triple(figure['value'], figure['unit'], figure['expanded_u'], _digits(figure['unit']))}"
    value = figure["value"][0]
    return f"{figure['label']} {value:.{_digits(figure['unit']) + 1}f} {figure['unit']}"


def trend_lines(serial: str, calibrations: int, result: dict[str, Any], channel: str, labelled: bool = False) -> list[str]:
    """`rig registry trend`: each calibration's figures at the reference temperature, then each one's drift per
    year, in its unit (one channel's; named where the sensor has more than one)."""
    label = f" {channel}" if labelled else ""
    lines = [f"{serial}{label}: {calibrations} calibrations, figures at the reference temperature (± expanded, k = 2)"]
    for point in result["calibrations"]:
        lines.append(f"  {point['calibrated_at'][:10]}  " + "  ".join(
            f"{f['label']} {triple(f['value'], f['unit'], f['expanded_u'], _digits(f['unit']))}"
            for f in point["figures"].values()))
    withheld = result.get("drift_not_stated")
    if withheld:
        option = " (--min-span-days sets it)" if 0 < result["span_days"] < result["min_span_days"] else ""
        return [*lines, f"  drift per year: not stated: {withheld}{option}"]
    for name, drift in result["drift_per_year"].items():
        if drift is None:
            lines.append(f"  {name.replace('_', ' ')} drift: needs two calibrations at different times with its figures")
        else:
            lines.append(f"  {drift['label']} drift per year: "
                         + ", ".join(f"{axis} {_drift_text(d, drift['unit'])}" for axis, d in zip("xyz", drift["axes"])))
    return lines


def lot_lines(part: str, result: dict[str, Any], channel: str, labelled: bool = False) -> list[str]:
    """`rig registry stats`: the lot's yield, each figure's distribution per axis, the outliers (one channel's;
    named where the lot has more than one)."""
    judged = "none judged against acceptance limits"
    if result["judged"]:
        conditional = result.get("conditional", 0)
        judged = (f"{result['passed']} of {result['judged']} judged passed ({result['yield']:.1%})"
                  + (f", {conditional} conditional (inside a guard band: neither passed nor failed)" if conditional
                     else ""))
    label = f" {channel}" if labelled else ""
    lines = [f"{part}{label}: {result['sensors']} sensors ({result['calibrations']} calibrations), newest of each: "
             f"{judged}"]
    for distribution in result["distributions"].values():
        columns = distribution["axes"]
        name = f"{distribution['label']} ({distribution['unit']})"
        for axis, summary in zip("xyz" if len(columns) == 3 else " ", columns):
            if summary is not None:
                lines.append(f"  {name:<28} {axis}  median {summary['median']:+10.4g}  p5…p95 {summary['p5']:+.4g}…"
                             f"{summary['p95']:+.4g}  std {summary['std']:.3g}  (n {summary['n']})")
    for outlier in result["outliers"]:
        lines.append(f"  outlier: {outlier['serial']} (calibration {outlier['id']}) {outlier['figure']} "
                     f"{outlier['axis'] or ''} {outlier['value']:+.4g} (robust z {outlier['robust_z']:+.1f})")
    return lines


def _drift_text(drift: dict[str, float | None], unit: str) -> str:
    """`+0.12 ± 0.03 mg`; without stated uncertainties (hand-held fits) the slope alone, said so."""
    uncertainty = drift["expanded_uncertainty"]
    spread = f" ± {uncertainty:.2g}" if uncertainty is not None else " (uncertainty not stated)"
    return f"{drift['per_year']:+.4g}{spread} {unit}"


def triple(values: list[float] | None, unit: str, uncertainty: list[float] | None = None, digits: int = 3) -> str:
    """x/y/z of a figure (`+1.234/-0.500/+0.020 mg`), each with its uncertainty when given; `—` for none."""
    if values is None:
        return "—"
    if uncertainty is None:
        return "/".join(f"{v:+.{digits}f}" for v in values) + f" {unit}"
    return "/".join(f"{v:+.{digits}f}±{u:.{digits}f}" for v, u in zip(values, uncertainty)) + f" {unit}"


def public(row: dict[str, Any]) -> dict[str, Any]:
    """A row as JSON: times as ISO 8601 UTC, the stored fit left out (`rig registry export` gives it)."""
    return {k: (v.isoformat() + "Z" if isinstance(v, datetime) else v) for k, v in row.items() if k != "calibration"}
