"""`rig registry`: the lab's calibrations by serial number — register campaigns, list and show them, a
sensor's trend across recalibrations, a part's lot statistics, and its calibration exported again."""

from __future__ import annotations

import argparse
import json
from datetime import date, datetime
from pathlib import Path
from typing import Any

from accelcal_rig.errors import ConfigError


def registry_command(args: argparse.Namespace) -> int:
    return {"add": _add, "list": _list, "show": _show, "trend": _trend, "stats": _stats,
            "export": _export}[args.registry_command](args)


def open_registry(args: argparse.Namespace, upgrade: bool = False):  # noqa: ANN201 - imported late (SQLAlchemy)
    """The registry the command names: --registry, else the rig config's (--config), else the environment's,
    else the default file. Only a recording command (`upgrade`) migrates an older schema."""
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import configured, registry_url

    from_config = None
    if getattr(args, "config", None) is not None:
        from accelcal_rig.config.load import load_rig

        rig = load_rig(args.config)
        from_config = configured(rig.model.registry, rig.path)
    return Registry.open(registry_url(args.registry, from_config), upgrade=upgrade)


def register(url: str, entries: list[dict[str, Any]]) -> str:
    """Record entries in the registry at `url`; one line saying what happened (for `rig run`/`rig fit`)."""
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import described

    added, already = Registry.open(url, upgrade=True).add(entries)
    tail = f", {already} registered already" if already else ""
    return f"registry   {len(added)} calibration{'s' if len(added) != 1 else ''} recorded in {described(url)}{tail}"


def _add(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.entries import campaign_entries

    if args.calibration is not None and len(args.files) != 1:
        raise ConfigError("--calibration names the calibration of one campaign file: give one FILE with it")
    registry = open_registry(args, upgrade=True)
    for path in args.files:
        added, already = registry.add(campaign_entries(path, args.calibration))
        print(f"{path}: {len(added)} added" + (f", {already} registered already" if already else ""))
    return 0


def _list(args: argparse.Namespace) -> int:
    since = _since(args.since) if args.since else None
    rows = open_registry(args).calibrations(serial=args.serial, part=args.part, since=since, verdict=args.verdict,
                                            limit=args.limit)
    if args.json:
        print(json.dumps([_public(r) for r in rows], indent=2))
        return 0
    if not rows:
        print("no calibrations match")
        return 0
    print(f"{'id':>6}  {'serial':<16} {'part':<8} {'calibrated (UTC)':<19} {'verdict':<7} {'valid °C':<15} "
          f"{'procedure':<22} source")
    for r in rows:
        print(f"{r['id']:>6}  {r['serial']:<16} {r['part']:<8} {r['calibrated_at']:%Y-%m-%d %H:%M:%S} "
              f"{r['verdict'] or '—':<7} {r['valid_from_c']:>6.1f}…{r['valid_to_c']:<7.1f} {r['procedure'][:22]:<22} "
              f"{Path(r['source_path']).name}{' (simulated)' if r['simulated'] else ''}")
    return 0


def _show(args: argparse.Namespace) -> int:
    registry = open_registry(args)
    rows = registry.calibrations(serial=args.serial)
    if not rows:
        raise ConfigError(f"serial {args.serial}: no calibration in the registry")
    current = registry.current(args.serial, simulated=args.simulated)
    if args.json:
        print(json.dumps({"serial": args.serial, "current": _public(current) if current else None,
                          "history": [_public(r) for r in rows]}, indent=2))
        return 0
    if current is None:
        newest = next((r for r in rows if args.simulated or not r["simulated"]), None)
        why = ("its newest calibration failed its acceptance limits" if newest is not None
               else "only dry runs (simulated) are recorded: --simulated shows them")
        print(f"{args.serial}: no valid calibration ({why})")
    else:
        simulated = " (SIMULATED: a dry run)" if current["simulated"] else ""
        print(f"{args.serial} ({current['part']}): valid calibration {current['id']}{simulated}, "
              f"measured {current['calibrated_at']:%Y-%m-%d} "
              f"by {current['procedure']} on {current['rig']}, {current['valid_from_c']:.1f}…{current['valid_to_c']:.1f} °C, "
              f"verdict {current['verdict'] or 'none stated'}")
        print(f"  at {current['reference_c']:g} °C: bias {_triple(current['bias_mg'], 'mg', current['bias_uncertainty_mg'])}; "
              f"scale error {_triple(current['scale_error_ppm'], 'ppm', current['scale_uncertainty_ppm'], 0)}; "
              f"non-orthogonality ≤ {current['nonorthogonality_mrad']:.3f} mrad")
        print(f"  source {current['source_path']} (SHA-256 {current['source_sha256'][:16]}…), software "
              f"{current['software_version']}")
    print(f"history ({len(rows)}):")
    for r in rows:
        print(f"  {r['id']:>6}  {r['calibrated_at']:%Y-%m-%d %H:%M}  {r['verdict'] or '—':<4}  "
              f"bias {_triple(r['bias_mg'], 'mg')}  {Path(r['source_path']).name}"
              + (" (simulated)" if r["simulated"] else ""))
    return 0


def _trend(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.analysis import trend

    rows = _real_unless(args, open_registry(args).calibrations(serial=args.serial))
    if not rows:
        raise ConfigError(f"serial {args.serial}: no calibration in the registry" + _simulated_hint(args))
    result = trend(rows)
    if args.json:
        print(json.dumps({"serial": args.serial, **result}, indent=2))
        return 0
    print(f"{args.serial}: {len(rows)} calibrations, figures at the reference temperature (± expanded, k = 2)")
    for point in result["calibrations"]:
        print(f"  {point['calibrated_at'][:10]}  bias {_triple(point['bias_mg'], 'mg', point['bias_uncertainty_mg'])}"
              f"  scale {_triple(point['scale_error_ppm'], 'ppm', point['scale_uncertainty_ppm'], 0)}")
    for key, unit in (("bias_drift_mg_per_year", "mg"), ("scale_drift_ppm_per_year", "ppm")):
        drift = result[key]
        what = key.split("_drift")[0]
        if drift is None:
            print(f"  {what} drift: needs two calibrations at different times")
        else:
            print(f"  {what} drift per year: " + ", ".join(f"{axis} {_drift_text(d, unit)}" for axis, d in zip("xyz", drift)))
    return 0


def _stats(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.analysis import lot_statistics

    rows = _real_unless(args, open_registry(args).calibrations(part=args.part))
    if not rows:
        raise ConfigError(f"part {args.part}: no calibration in the registry" + _simulated_hint(args))
    result = lot_statistics(rows)
    if args.json:
        print(json.dumps({"part": args.part, **result}, indent=2))
        return 0
    judged = f"{result['passed']} of {result['judged']} judged passed ({result['yield']:.1%})" if result["judged"] \
        else "none judged against acceptance limits"
    print(f"{args.part}: {result['sensors']} sensors ({result['calibrations']} calibrations), newest of each: {judged}")
    for name, columns in result["distributions"].items():
        for axis, summary in zip("xyz" if len(columns) == 3 else " ", columns):
            if summary is not None:
                print(f"  {name:<22} {axis}  median {summary['median']:+10.4g}  p5…p95 {summary['p5']:+.4g}…"
                      f"{summary['p95']:+.4g}  std {summary['std']:.3g}  (n {summary['n']})")
    for outlier in result["outliers"]:
        print(f"  outlier: {outlier['serial']} (calibration {outlier['id']}) {outlier['figure']} "
              f"{outlier['axis'] or ''} {outlier['value']:+.4g} (robust z {outlier['robust_z']:+.1f})")
    return 0


def _export(args: argparse.Namespace) -> int:
    from accelcal_rig.export.flight_stack import StackOptions
    from accelcal_rig.export.formats import export, write_export
    from accelcal_rig.registry.entries import calibration_file_of

    registry = open_registry(args)
    if args.id is not None:
        row = registry.calibration(args.id)
        if row["serial"] != args.serial:
            raise ConfigError(f"calibration {args.id} is of {row['serial']}, not {args.serial}")
    else:
        found = registry.current(args.serial, simulated=args.simulated)
        if found is None:
            raise ConfigError(f"serial {args.serial}: no valid calibration in the registry" + _simulated_hint(args))
        row = registry.calibration(found["id"])
    if args.output is not None and not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    exported = export(calibration_file_of(row), args.format,
                      StackOptions(Path(f"registry calibration {row['id']}"), None, args.instance, args.device_id))
    return write_export(exported, args.format, args.output)


def _drift_text(drift: dict[str, float | None], unit: str) -> str:
    """`+0.12 ± 0.03 mg`; without stated uncertainties (hand-held fits) the slope alone, said so."""
    uncertainty = drift["expanded_uncertainty"]
    spread = f" ± {uncertainty:.2g}" if uncertainty is not None else " (uncertainty not stated)"
    return f"{drift['per_year']:+.4g}{spread} {unit}"


def _real_unless(args: argparse.Namespace, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Dry runs are rehearsals, not calibrations: left out unless --simulated."""
    return rows if args.simulated else [r for r in rows if not r["simulated"]]


def _simulated_hint(args: argparse.Namespace) -> str:
    return "" if args.simulated else " (dry runs are left out: --simulated includes them)"


def _since(text: str) -> datetime:
    try:
        return datetime.combine(date.fromisoformat(text), datetime.min.time())
    except ValueError:
        raise ConfigError(f"--since {text!r}: not a date (YYYY-MM-DD)") from None


def _triple(values: list[float] | None, unit: str, uncertainty: list[float] | None = None, digits: int = 3) -> str:
    if values is None:
        return "—"
    if uncertainty is None:
        return "/".join(f"{v:+.{digits}f}" for v in values) + f" {unit}"
    return "/".join(f"{v:+.{digits}f}±{u:.{digits}f}" for v, u in zip(values, uncertainty)) + f" {unit}"


def _public(row: dict[str, Any]) -> dict[str, Any]:
    """A row as JSON: times as ISO 8601 UTC, the stored fit left out (`rig registry export` gives it)."""
    return {k: (v.isoformat() + "Z" if isinstance(v, datetime) else v) for k, v in row.items() if k != "calibration"}
