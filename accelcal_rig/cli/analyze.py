"""`rig analyze`: the paper's other experiments on a campaign file — each computes with accelcal_rig.analysis,
prints its table or one JSON object (cli_format_analysis), and draws its figure on request."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from accelcal_rig.errors import ConfigError

if TYPE_CHECKING:
    from accelcal_rig.analysis.cooldown import CooldownResult
    from accelcal_rig.analysis.positions import SizeSummary
    from accelcal_rig.analysis.tilt import TiltRow
    from accelcal_rig.fit.calibration import ChannelCalibration
    from accelcal_rig.fit.lm import FreeParameters


def analyze(args: argparse.Namespace) -> int:
    """`rig analyze ANALYSIS`: run it on the campaign, print its table (or JSON), draw its figure."""
    return {"positions": _analyze_positions, "tilt": _analyze_tilt, "cooldown": _analyze_cooldown}[args.analysis](args)


def _analyze_cooldown(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.format_analysis import cooldown_json, cooldown_lines

    results = cooldown_results(args.campaign, args.calibration, args.setpoint, args.figure)
    print(json.dumps(cooldown_json(args.calibration, results)) if args.json
          else "\n".join(cooldown_lines(args.campaign, args.calibration, results, args.figure)))
    return 0


def _analyze_tilt(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.format_analysis import tilt_json, tilt_lines

    setpoint, rows, outside = tilt_results(args.campaign, args.calibration, args.setpoint)
    print(json.dumps(tilt_json(setpoint, args.calibration, outside, rows)) if args.json
          else "\n".join(tilt_lines(args.campaign, setpoint, args.calibration, outside, rows)))
    return 0


def _analyze_positions(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.format_analysis import positions_json, positions_lines

    setpoint, mode, rows, floors = positions_results(args)
    print(json.dumps(positions_json(setpoint, mode, floors, rows)) if args.json
          else "\n".join(positions_lines(args.campaign, setpoint, mode, args.subsets, floors, rows, args.figure)))
    return 0


def cooldown_results(campaign: Path, calibration_path: Path, setpoint: float | None,
                     figure: Path | None) -> list[CooldownResult]:
    """Each DUT's temperature coefficients over a free cool-down, before and after compensation; the figure
    drawn if asked for."""
    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.cooldown import analyse_cooldown

    if figure is not None:
        _check_figure_path(figure)
    _, duts, _ = poses_at_setpoint(campaign, setpoint)
    accelerometers = _accelerometers_of(calibration_path, campaign, list(duts))
    results = [analyse_cooldown(poses, accelerometers[serial]) for serial, poses in duts.items()]
    if figure is not None:
        from accelcal_rig.report.analysis_figures import cooldown_figure

        cooldown_figure(results, figure)
    return results


def tilt_results(campaign: Path, calibration_path: Path,
                 setpoint_c: float | None) -> tuple[float, dict[str, list[TiltRow]], list[str]]:
    """The setpoint, every DUT's tilt rows, and the DUTs whose temperatures lie outside their calibration's
    range (one note each)."""
    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.tilt import tilt_rows

    setpoint, duts, numbers = poses_at_setpoint(campaign, setpoint_c)
    accelerometers = _accelerometers_of(calibration_path, campaign, list(duts))
    rows = {serial: tilt_rows(poses, numbers, accelerometers[serial]) for serial, poses in duts.items()}
    outside = [f"{s} ({duts[s].temperature_c.min():.1f}…{duts[s].temperature_c.max():.1f} °C outside "
               f"{accelerometers[s].validity_c[0]:.1f}…{accelerometers[s].validity_c[1]:.1f} °C)"
               for s in duts if not (accelerometers[s].validity_c[0] <= duts[s].temperature_c.min()
                                     and duts[s].temperature_c.max() <= accelerometers[s].validity_c[1])]
    return setpoint, rows, outside


def positions_results(args: argparse.Namespace) -> tuple[float, str, list[SizeSummary], dict[str, float]]:
    """The setpoint, the fit mode, each DUT's scores per subset size and its noise floor; the figure drawn
    if asked for."""
    import numpy as np

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.positions import floor_mg, score_subsets, summarise

    sizes = _subset_sizes(args.sizes, args.subsets)
    if args.figure is not None:
        _check_figure_path(args.figure)
    setpoint, duts, _ = poses_at_setpoint(args.campaign, args.setpoint)
    mode, free = _positions_fit(args.campaign, args.mode)
    rows, floors = [], {}
    for serial, poses in duts.items():
        scores = score_subsets(poses, sizes, mode, free, args.subsets, np.random.default_rng(args.seed))  # type: ignore[arg-type]
        rows += summarise(serial, scores)
        floors[serial] = floor_mg(poses)
    if args.figure is not None:
        from accelcal_rig.report.analysis_figures import positions_figure

        positions_figure(rows, floors, mode, args.figure)
    return setpoint, mode, rows, floors


def _subset_sizes(text: str | None, subsets: int) -> tuple[int, ...]:
    from accelcal_rig.analysis.positions import PAPER_SIZES

    try:
        sizes = tuple(int(v) for v in text.split(",")) if text else PAPER_SIZES
    except ValueError:
        raise ConfigError(f"--sizes: {text!r}: expected whole numbers separated by commas") from None
    if min(sizes) < 6 or subsets < 1:
        raise ConfigError("--sizes: at least 6 positions per subset; --subsets: at least 1")
    return sizes


def _positions_fit(campaign: Path, requested: str | None) -> tuple[str, FreeParameters]:
    """The mode to refit with (the one asked for, else the campaign's; a measure-only campaign: reference) and
    the parameters the campaign frees."""
    from accelcal_rig.fit.recorded_options import NO_FIT, recorded_options, requested_mode
    from accelcal_rig.store.read import load_campaign

    attrs = load_campaign(campaign).attrs
    recorded = requested_mode(attrs)
    mode = requested or ("reference" if recorded == NO_FIT else recorded)  # measure-only: the table's reference
    options = recorded_options(attrs, str(campaign), mode=mode)
    assert options is not None
    return mode, options.free


def _accelerometers_of(calibration_path: Path, campaign: Path, serials: list[str]) -> dict[str, ChannelCalibration]:
    """Each DUT's accelerometer calibration (the analyses of a tilt check and a cool-down are of acceleration)."""
    from accelcal_rig.analysis.campaign_poses import ACCELERATION
    from accelcal_rig.fit.calibration import load_calibration

    accelerometers = load_calibration(calibration_path).of_quantity(ACCELERATION)
    missing = [serial for serial in serials if serial not in accelerometers]
    if missing:
        raise ConfigError(f"{calibration_path}: no accelerometer calibration for {', '.join(missing)} of {campaign} "
                          f"(it has {', '.join(accelerometers) or 'none'})")
    return accelerometers


def _check_figure_path(path: Path) -> None:
    from accelcal_rig.report.figures import pyplot

    pyplot()  # a missing extra is a one-line error before any work
    if not path.parent.is_dir():
        raise ConfigError(f"{path}: folder {path.parent} does not exist")
