"""What every group of commands shares: the one-line parser, bounded numbers, a subcommand whose --help ends
with an example, and the options several commands take alike."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

FAULTS_HELP = ("fault injection into the simulators, e.g. rate=0.05,kinds=drop+corrupt or "
               "chamber_stall_after_min=60 (keys of simulation.faults)")

REGISTRY_HELP = ("the registry: a postgresql:// URL or an SQLite file (default: the rig config's registry:, "
                 "else $ACCELCAL_REGISTRY, else ~/.local/share/accelcal-rig/registry.sqlite; a dry run's "
                 "calibrations: $ACCELCAL_DRY_RUN_REGISTRY, else dry-runs.sqlite beside that file)")

#: The built-in chamber profiles a dry run or `rig sim` may swap in (accelcal_rig.protocols.chamber_registers).
CHAMBER_PROFILE_HELP = ("simulate a chamber of this built-in profile instead of the rig's (watlow-f4, watlow-f4t, "
                        "espec-p300, thermotron-8800, simserv, watlow-f4t-scpi)")

#: `commands.add_parser(…)` of one level of subcommands.
Commands = argparse._SubParsersAction


class Parser(argparse.ArgumentParser):
    """Command-line mistakes are one line too (argparse would print its usage above them)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def number(low: float, high: float, unit: str = "", integer: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number within [low, high]."""
    def parse(text: str) -> float:
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a{'' if integer else ' finite'} number") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"{text} is outside {low:g} … {high:g}{' ' + unit if unit else ''}")
        return value
    return parse


TEMPERATURE = number(-100.0, 300.0, "°C")
SEED = number(0, 2**32 - 1, integer=True)


def command(commands: Commands, name: str, summary: str, description: str, example: str) -> argparse.ArgumentParser:
    """A subcommand whose --help ends with an example."""
    return commands.add_parser(name, help=summary, description=description, epilog=f"example:\n  {example}",
                               formatter_class=argparse.RawDescriptionHelpFormatter)


def registry_option(command: argparse.ArgumentParser) -> None:
    """`--registry URL`: the same on every command that records or reads calibrations."""
    command.add_argument("--registry", metavar="URL", help=REGISTRY_HELP)


def campaign_output_options(command: argparse.ArgumentParser) -> None:
    """What `rig run` and `rig resume` share: where the fit writes, and how much the console says."""
    command.add_argument("--calibration", type=Path,
                         help="calibration file the final fit writes (default: beside the campaign, .calibration.yaml)")
    command.add_argument("-v", "--verbose", action="store_true", help="log every transition and pose")
    command.add_argument("-q", "--quiet", action="store_true", help="print only warnings and the summary")
    fail_on_reject(command)
    command.add_argument("--certificates", type=Path, help="folder of the DUTs' certificates written after the fit "
                                                            "(default: beside the campaign, .certificates)")
    certificate_options(command)
    registry_option(command)
    command.add_argument("--no-publish", action="store_true",
                         help="do not publish the campaign's live status to the registry (what rig serve --registry "
                              "shows of every rig)")


def certificate_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("--operator", default="", help="who performed the calibration (on the certificates)")
    command.add_argument("--no-pdf", action="store_true", help="HTML certificates only")


def fail_on_reject(command: argparse.ArgumentParser) -> None:
    command.add_argument("--fail-on-reject", action="store_true",
                         help="exit with status 3 when any DUT fails the procedure's acceptance limits")
