"""The grammar of `rig analyze ANALYSIS`: the paper's other experiments on a campaign file."""

from __future__ import annotations

import argparse
from pathlib import Path

from accelcal_rig.cli.grammar.common import SEED, TEMPERATURE, Commands, command, number


def add_analysis_commands(commands: Commands) -> None:
    """`rig analyze positions | tilt | cooldown`."""
    analyze = command(commands, "analyze", "the paper's other experiments on a campaign file: positions, tilt, cooldown",
                      "Analyses of campaign files beyond the calibration: how many positions a calibration "
                      "needs (positions), tilt angles before and after calibration (tilt), the temperature "
                      "coefficient during a free cool-down (cooldown).",
                      "rig analyze positions campaign.h5 --figure positions.png")
    analyses = analyze.add_subparsers(dest="analysis", required=True, metavar="ANALYSIS")
    for add in (_add_positions, _add_tilt, _add_cooldown):
        add(analyses)


def _analysis(analyses: Commands, name: str, summary: str, description: str, example: str, *, calibration: bool,
              figure: bool) -> argparse.ArgumentParser:
    """A `rig analyze` subcommand with the arguments every analysis shares."""
    analysis = command(analyses, name, summary, description, example)
    analysis.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    if calibration:
        analysis.add_argument("--calibration", type=Path, required=True, help="calibration file (YAML) of the same DUTs")
    analysis.add_argument("--setpoint", type=TEMPERATURE, help="the setpoint to analyse (default: the file's only one)")
    if figure:
        analysis.add_argument("--figure", type=Path, help="write the figure (PNG) here")
    analysis.add_argument("--json", action="store_true", help="print one JSON object")
    return analysis


def _add_positions(analyses: Commands) -> None:
    positions = _analysis(
        analyses, "positions", "refit on subsets of 1296 … 12 positions, score on the rest",
        "Refit the error model on subsets of the poses of one setpoint, of the sizes of the paper's Table 4 "
        "(several random subsets and one evenly spread subset each), and report the RMSE of |g| on the poses "
        "each fit did not use (paper Fig. 8). Made for procedures/positions-study.yaml (1296 orientations).",
        "rig analyze positions campaign.h5 --figure positions.png", calibration=False, figure=True)
    positions.add_argument("--sizes", help="comma-separated subset sizes (default: the paper's 1296,648,…,12)")
    positions.add_argument("--subsets", type=number(1, 1000, integer=True), default=10,
                           help="random subsets per size (default 10)")
    positions.add_argument("--seed", type=SEED, default=0, help="seed of the random subsets (default 0)")
    positions.add_argument("--mode", choices=["reference", "norm-only"], help="default: the campaign's fit mode")


def _add_tilt(analyses: Commands) -> None:
    _analysis(
        analyses, "tilt", "pitch and roll before and after a calibration, against the reference",
        "For every pose of one setpoint and every DUT: the reference pitch and roll (paper Eq. 10) from the "
        "orientation the turntable set, those measured raw and after compensation with the calibration, and "
        "the SEOQ (|before − after| relative to 30°), as in the paper's Table 5. Made for "
        "procedures/tilt-check.yaml.",
        "rig analyze tilt tilt.h5 --calibration campaign.calibration.yaml", calibration=True, figure=False)


def _add_cooldown(analyses: Commands) -> None:
    _analysis(
        analyses, "cooldown", "temperature coefficient per axis during a free cool-down",
        "For every DUT of a cool-down campaign (procedures/cooldown-60c.yaml): the slope of each axis's output "
        "against the DUT's own temperature, in µg/K, before and after compensation with the calibration "
        "(paper: 1346 → 37 µg/K), and the output's span; the figure shows the outputs over the cool-down "
        "(paper Fig. 11).",
        "rig analyze cooldown cooldown.h5 --calibration campaign.calibration.yaml --figure cool.png",
        calibration=True, figure=True)
