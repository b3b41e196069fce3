"""`rig registry`: the lab's calibrations by serial number — register campaigns, list and show them, a
sensor's trend across recalibrations, a part's lot statistics, and its calibration exported again; and what
`rig run`, `rig fit` and `rig fit-recording` record. The lines they print are cli_format_registry's."""

from __future__ import annotations

import argparse
import json
from datetime import date, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from accelcal_rig.cli.format_registry import calibration_table, lot_lines, public, sensor_lines, trend_lines
from accelcal_rig.cli.registry_access import campaign_entries, from_config, open_registry
from accelcal_rig.errors import ConfigError

if TYPE_CHECKING:
    pass


def registry_command(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.approval import audit_command, certificate_command, user_command

    return {"add": _add, "list": _list, "show": _show, "trend": _trend, "stats": _stats,
            "export": _export, "user": user_command, "audit": audit_command,
            "certificate": certificate_command}[args.registry_command](args)


def _add(args: argparse.Namespace) -> int:
    if args.calibration is not None and len(args.files) != 1:
        raise ConfigError("--calibration names the calibration of one campaign file: give one FILE with it")
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import described, recording_url

    named = args.registry or from_config(args)  # a registry named here takes dry runs too
    opened: dict[str, Registry] = {}
    for path in args.files:
        entries = campaign_entries(path, args.calibration)
        simulated = any(entry["simulated"] for entry in entries)
        url = recording_url(named, None, simulated)
        if url not in opened:
            opened[url] = Registry.open(url, upgrade=True)
        added, already = opened[url].add(entries)
        print(f"{path}: {len(added)} added" + (f", {already} registered already" if already else "")
              + (f" (a dry run: in {described(url)}, apart from the lab's registry)" if simulated and not named else ""))
    return 0


def _list(args: argparse.Namespace) -> int:
    """The calibrations recorded; none (not an error) in a registry not made yet, which listing leaves unmade."""
    from accelcal_rig.registry.location import described, recording_url, registry_url

    since = _since(args.since) if args.since else None
    url = registry_url(args.registry, from_config(args))
    registry = None if _not_made(url) else open_registry(args)
    rows = [] if registry is None else registry.calibrations(
        serial=args.serial, part=args.part, since=since, verdict=args.verdict, limit=args.limit,
        channel=args.channel, simulated=args.made)
    if args.json:
        print(json.dumps([public(r) for r in rows], indent=2))
        return 0
    dry_runs = recording_url(None, None, simulated=True)
    elsewhere = None if rows or args.made is False or url == dry_runs else described(dry_runs)
    print("\n".join(calibration_table(rows, elsewhere)))
    return 0


def _not_made(url: str) -> bool:
    """An SQLite registry whose file does not exist yet (a recording command makes it)."""
    return url.startswith("sqlite:///") and not Path(url.removeprefix("sqlite:///")).exists()


def _show(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.analysis import by_channel

    registry = open_registry(args)
    rows = registry.calibrations(serial=args.serial, channel=args.channel)
    if not rows:
        raise ConfigError(f"serial {args.serial}: no calibration{_of_channel(args)} in the registry")
    current = {channel: registry.current(args.serial, simulated=args.simulated, channel=channel)
               for channel in by_channel(rows)}
    if args.json:
        print(json.dumps({"serial": args.serial,
                          "current": {channel: public(row) if row else None for channel, row in current.items()},
                          "history": [public(r) for r in rows]}, indent=2))
    else:
        why = {channel: ("" if args.simulated else registry.why_not_valid(args.serial, channel))
               for channel, row in current.items() if row is None}
        print("\n".join(sensor_lines(args.serial, current, rows, args.simulated, why)))
    return 0


def _trend(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.analysis import MIN_SPAN_DAYS, by_channel, trend

    rows = _real_unless(args, open_registry(args).calibrations(serial=args.serial, channel=args.channel))
    if not rows:
        raise ConfigError(f"serial {args.serial}: no calibration{_of_channel(args)} in the registry"
                          + _simulated_hint(args))
    span = MIN_SPAN_DAYS if args.min_span_days is None else args.min_span_days
    results = {channel: (len(of), trend(of, channel, span)) for channel, of in by_channel(rows).items()}
    if args.json:
        print(json.dumps({"serial": args.serial, "channels": {c: r for c, (_, r) in results.items()}}, indent=2))
    else:
        print("\n".join(line for channel, (n, result) in results.items()
                        for line in trend_lines(args.serial, n, result, channel, len(results) > 1)))
    return 0


def _stats(args: argparse.Namespace) -> int:
    from accelcal_rig.registry.analysis import by_channel, lot_statistics

    rows = _real_unless(args, open_registry(args).calibrations(part=args.part, channel=args.channel))
    if not rows:
        raise ConfigError(f"part {args.part}: no calibration{_of_channel(args)} in the registry"
                          + _simulated_hint(args))
    results = {channel: lot_statistics(of, channel) for channel, of in by_channel(rows).items()}
    print(json.dumps({"part": args.part, "channels": results}, indent=2) if args.json else
          "\n".join(line for channel, result in results.items()
                    for line in lot_lines(args.part, result, channel, len(results) > 1)))
    return 0


def _export(args: argparse.Namespace) -> int:
    from accelcal_rig.export.flight_stack import StackOptions
    from accelcal_rig.export.formats import export, write_export
    from accelcal_rig.registry.entries import calibration_file_of

    registry = open_registry(args)
    if args.id is not None:
        rows = [registry.calibration(args.id)]
        if rows[0]["serial"] != args.serial:
            raise ConfigError(f"calibration {args.id} is of {rows[0]['serial']}, not {args.serial}")
    else:  # the sensor's valid calibration of each channel it has one of
        valid = [found for channel in registry.channels(args.serial)
                 if (found := registry.current(args.serial, simulated=args.simulated, channel=channel)) is not None]
        if not valid:
            raise ConfigError(f"serial {args.serial}: no valid calibration in the registry" + (
                f" ({'; '.join(registry.why_not_valid(args.serial, c) for c in registry.channels(args.serial))})"
                if not args.simulated and registry.calibrations(serial=args.serial, simulated=False)
                else _simulated_hint(args)))
        rows = [registry.calibration(found["id"]) for found in valid]
    if args.output is not None and not args.output.parent.is_dir():
        raise ConfigError(f"{args.output}: folder {args.output.parent} does not exist")
    ids = ", ".join(str(row["id"]) for row in rows)
    exported = export(calibration_file_of(rows), args.format,
                      StackOptions(Path(f"registry calibration {ids}"), None, args.instance, args.device_id))
    return write_export(exported, args.format, args.output)


def _real_unless(args: argparse.Namespace, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Dry runs are rehearsals, not calibrations: left out unless --simulated."""
    return rows if args.simulated else [r for r in rows if not r["simulated"]]


def _of_channel(args: argparse.Namespace) -> str:
    return f" of the {args.channel} channel" if getattr(args, "channel", None) else ""


def _simulated_hint(args: argparse.Namespace) -> str:
    return "" if args.simulated else " (dry runs are left out: --simulated includes them)"


def _since(text: str) -> datetime:
    try:
        return datetime.combine(date.fromisoformat(text), datetime.min.time())
    except ValueError:
        raise ConfigError(f"--since {text!r}: not a date (YYYY-MM-DD)") from None
