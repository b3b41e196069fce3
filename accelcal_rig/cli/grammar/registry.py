"""The grammar of `rig registry ACTION`: the lab's calibrations by serial number."""

from __future__ import annotations

import argparse
from pathlib import Path

from accelcal_rig.cli.grammar.approval import add_approval_actions
from accelcal_rig.cli.grammar.common import Commands, command, number, registry_option


def add_registry_commands(commands: Commands) -> None:
    """`rig registry add | list | show | export | trend | stats | user | audit | certificate`."""
    registry = command(commands, "registry", "the lab's calibrations by serial number: add, list, show, export, "
                       "trend, stats",
                       "Every finished fit is recorded by DUT serial: rig run, rig fit and rig fit-recording do it "
                       "themselves; rig registry add records campaigns fitted before (idempotent: the same "
                       "file again adds nothing). The database is an SQLite file by default, or PostgreSQL for "
                       "several rigs (see docs/registry.md).",
                       "rig registry show ADX355-A001")
    actions = registry.add_subparsers(dest="registry_command", required=True, metavar="ACTION")
    for add in (_add_add, _add_list, _add_show, _add_export, _add_trend, _add_stats):
        add(actions)
    add_approval_actions(actions)   # user, audit, certificate


def _action(actions: Commands, name: str, summary: str, example: str) -> argparse.ArgumentParser:
    """A registry action: its summary is its description too; every action takes --registry and --config."""
    action = command(actions, name, summary, summary[0].upper() + summary[1:] + ".", example)
    registry_option(action)
    action.add_argument("--config", type=Path, metavar="RIG", help="rig config whose registry: to use")
    return action


def _add_add(actions: Commands) -> None:
    add = _action(actions, "add", "record finished campaigns and their calibrations", "rig registry add campaign.h5")
    add.add_argument("files", type=Path, nargs="+", metavar="FILE", help="campaign file (HDF5)")
    add.add_argument("--calibration", type=Path, help="its calibration (default: FILE.calibration.yaml beside it)")


def _add_list(actions: Commands) -> None:
    listing = _action(actions, "list", "calibrations, newest first, filtered",
                      "rig registry list --part adxl355 --since 2026-01-01")
    listing.add_argument("--serial", help="only this DUT")
    listing.add_argument("--part", help="only this part (adxl355, adxl357, …)")
    listing.add_argument("--since", metavar="DATE", help="only those calibrated on or after this date (YYYY-MM-DD)")
    listing.add_argument("--verdict", choices=["PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"],
                         help="only those with this verdict (CONDITIONAL: inside a guard band; NOT JUDGED: no "
                              "acceptance limits stated)")
    listing.add_argument("--limit", type=number(1, 10_000_000, integer=True), help="at most this many")
    _channel_option(listing)
    made = listing.add_mutually_exclusive_group()
    made.add_argument("--simulated", dest="made", action="store_const", const=True,
                      help="only dry runs (simulated campaigns)")
    made.add_argument("--real", dest="made", action="store_const", const=False,
                      help="only calibrations measured on a real rig")
    listing.add_argument("--json", action="store_true", help="one JSON list")


def _add_show(actions: Commands) -> None:
    show = _action(actions, "show", "a sensor's valid calibration and its history", "rig registry show ADX355-A001")
    show.add_argument("serial")
    _channel_option(show)
    show.add_argument("--json", action="store_true", help="one JSON object")
    _simulated_option(show)


def _add_export(actions: Commands) -> None:
    export = _action(actions, "export", "a sensor's valid calibration (or one by id) as a file other tools read",
                     "rig registry export ADX355-A001 --format c-header -o accel.h")
    export.add_argument("serial")
    export.add_argument("--format", required=True, choices=["json", "csv", "c-header", "px4-params", "ardupilot-params"],
                        help="what to write (as rig export)")
    export.add_argument("--id", type=number(1, 2**63 - 1, integer=True), help="this calibration, not the valid one")
    export.add_argument("--instance", type=number(0, 3, integer=True), help="px4-params, ardupilot-params: as rig export")
    export.add_argument("--device-id", type=number(1, 2**31 - 1, integer=True), help="px4-params: as rig export")
    export.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
    _simulated_option(export)


def _add_trend(actions: Commands) -> None:
    trend = _action(actions, "trend", "bias and scale at the reference temperature across recalibrations: ageing drift",
                    "rig registry trend ADX355-A001")
    trend.add_argument("serial")
    _channel_option(trend)
    trend.add_argument("--min-span-days", type=number(0, 36525, "days"), metavar="DAYS",
                       help="state a drift per year only from calibrations spanning at least this long (default 30)")
    trend.add_argument("--json", action="store_true", help="one JSON object")
    _simulated_option(trend)


def _add_stats(actions: Commands) -> None:
    stats = _action(actions, "stats", "a part's lot: yield, distributions of bias, scale and non-orthogonality, outliers",
                    "rig registry stats --part adxl355")
    stats.add_argument("--part", required=True)
    _channel_option(stats)
    stats.add_argument("--json", action="store_true", help="one JSON object")
    _simulated_option(stats)


def _channel_option(action: argparse.ArgumentParser) -> None:
    action.add_argument("--channel", metavar="CHANNEL",
                        help="only this channel of the DUTs, as their parts name it: accel, gyro, … (default: every "
                             "channel the registry holds, each named)")


def _simulated_option(action: argparse.ArgumentParser) -> None:
    action.add_argument("--simulated", action="store_true", help="count dry runs too (left out by default)")
