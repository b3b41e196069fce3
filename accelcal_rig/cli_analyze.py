"""`rig analyze`: the paper's other experiments on a campaign file — each computes with accelcal_rig.analysis,
prints its table or one JSON object, and draws its figure on request."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from accelcal_rig.errors import ConfigError


def analyze(args: argparse.Namespace) -> int:
    """`rig analyze ANALYSIS`: run it on the campaign, print its table (or JSON), draw its figure."""
    return {"positions": _analyze_positions, "tilt": _analyze_tilt, "cooldown": _analyze_cooldown}[args.analysis](args)


def _calibrations_for(calibration_path: Path, campaign: Path, serials: list[str]):  # noqa: ANN202
    from accelcal_rig.fit.calibration import load_calibration

    calibration = load_calibration(calibration_path)
    missing = [serial for serial in serials if serial not in calibration.sensors]
    if missing:
        raise ConfigError(f"{calibration_path}: no calibration for {', '.join(missing)} of {campaign} "
                          f"(it has {', '.join(calibration.sensors)})")
    return calibration


def _analyze_cooldown(args: argparse.Namespace) -> int:
    import dataclasses

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.cooldown import analyse_cooldown
    from accelcal_rig.fit.calibration import plain

    if args.figure is not None:
        _check_figure_path(args.figure)
    _, duts, _ = poses_at_setpoint(args.campaign, args.setpoint)
    calibration = _calibrations_for(args.calibration, args.campaign, list(duts))
    results = [analyse_cooldown(poses, calibration.sensors[serial]) for serial, poses in duts.items()]
    if args.figure is not None:
        from accelcal_rig.report.analysis_figures import cooldown_figure

        cooldown_figure(results, args.figure)
    if args.json:
        print(json.dumps(plain({"calibration": str(args.calibration), "sensors": [
            {k: v for k, v in dataclasses.asdict(r).items() if k not in ("t_s", "before_g", "after_g")}
            | {"records": len(r.t_s)} for r in results]})))
        return 0
    print(f"{args.campaign}: free cool-down, temperature coefficient per axis (µg/K) with {args.calibration}")
    print(f"{'sensor':14s} {'records':>7s} {'from … to (°C)':>16s} {'before x, y, z':>26s} {'after x, y, z':>26s}")
    for r in results:
        before = " ".join(f"{v:+8.1f}" for v in r.coefficient_before_ug_per_k)
        after = " ".join(f"{v:+8.2f}" for v in r.coefficient_after_ug_per_k)
        print(f"{r.serial:14s} {len(r.t_s):7d} {r.temperature_c.max():7.1f} … {r.temperature_c.min():5.1f} "
              f"{before:>26s} {after:>26s}")
        if r.outside_range:
            print(f"  warning: {r.outside_range} records outside the calibrated range: clamped or extrapolated as "
                  "the calibration file says")
    if args.figure is not None:
        print(f"figure → {args.figure}")
    return 0


def _analyze_tilt(args: argparse.Namespace) -> int:
    import dataclasses

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.tilt import tilt_rows, worst_errors_deg
    from accelcal_rig.fit.calibration import plain

    setpoint, duts, numbers = poses_at_setpoint(args.campaign, args.setpoint)
    calibration = _calibrations_for(args.calibration, args.campaign, list(duts))
    rows = {serial: tilt_rows(poses, numbers, calibration.sensors[serial]) for serial, poses in duts.items()}
    outside = [f"{s} ({duts[s].temperature_c.min():.1f}…{duts[s].temperature_c.max():.1f} °C outside "
               f"{calibration.sensors[s].validity_c[0]:.1f}…{calibration.sensors[s].validity_c[1]:.1f} °C)"
               for s in duts if not (calibration.sensors[s].validity_c[0] <= duts[s].temperature_c.min()
                                     and duts[s].temperature_c.max() <= calibration.sensors[s].validity_c[1])]
    if args.json:
        print(json.dumps(plain({"setpoint_c": setpoint, "calibration": str(args.calibration), "outside_range": outside,
                                "rows": [dataclasses.asdict(r) for sensor in rows.values() for r in sensor]})))
        return 0
    print(f"{args.campaign} at {setpoint:g} °C with {args.calibration}: pitch; roll (degrees), paper Eq. 10")
    print(f"{'sensor':14s} {'pose':>4s} {'reference':>16s} {'without calibration':>20s} {'after calibration':>20s} "
          f"{'SEOQ (%)':>12s}")
    for serial, sensor_rows in rows.items():
        for r in sensor_rows:
            pair = lambda v, d: f"{v[0]:.{d}f}; {v[1]:.{d}f}"  # noqa: E731
            print(f"{serial:14s} {r.pose_number:4d} {pair(r.reference_deg, 2):>16s} {pair(r.before_deg, 3):>20s} "
                  f"{pair(r.after_deg, 3):>20s} {pair(r.seoq_percent, 2):>12s}")
        before, after = worst_errors_deg(sensor_rows)
        print(f"{serial:14s} worst |error|: {before:.3f}° without, {after:.4f}° after calibration")
    for note in outside:
        print(f"warning: {note}: the calibration was clamped to its range")
    return 0


def _analyze_positions(args: argparse.Namespace) -> int:
    import dataclasses

    import numpy as np

    from accelcal_rig.analysis.campaign_poses import poses_at_setpoint
    from accelcal_rig.analysis.positions import PAPER_SIZES, floor_mg, score_subsets, summarise
    from accelcal_rig.fit.calibration import plain
    from accelcal_rig.fit.recorded_options import NO_FIT, recorded_options, requested_mode
    from accelcal_rig.store.read import load_campaign

    try:
        sizes = tuple(int(v) for v in args.sizes.split(",")) if args.sizes else PAPER_SIZES
    except ValueError:
        raise ConfigError(f"--sizes: {args.sizes!r}: expected whole numbers separated by commas") from None
    if min(sizes) < 6 or args.subsets < 1:
        raise ConfigError("--sizes: at least 6 positions per subset; --subsets: at least 1")
    if args.figure is not None:
        _check_figure_path(args.figure)
    setpoint, duts, _ = poses_at_setpoint(args.campaign, args.setpoint)
    attrs = load_campaign(args.campaign).attrs
    recorded = requested_mode(attrs)
    mode = args.mode or ("reference" if recorded == NO_FIT else recorded)  # measure-only: the table's reference
    options = recorded_options(attrs, str(args.campaign), mode=mode)
    assert options is not None
    free = options.free
    rows, floors = [], {}
    for serial, poses in duts.items():
        scores = score_subsets(poses, sizes, mode, free, args.subsets, np.random.default_rng(args.seed))  # type: ignore[arg-type]
        rows += summarise(serial, scores)
        floors[serial] = floor_mg(poses)
    if args.figure is not None:
        from accelcal_rig.report.analysis_figures import positions_figure

        positions_figure(rows, floors, mode, args.figure)
    if args.json:
        print(json.dumps(plain({"setpoint_c": setpoint, "mode": mode, "noise_floor_mg": floors,
                                "sizes": [dataclasses.asdict(r) for r in rows]})))
        return 0
    print(f"{args.campaign}: {mode} fits at {setpoint:g} °C, RMSE of |g| on the poses each fit left out (mg); "
          f"{args.subsets} random subsets per size")
    print(f"{'sensor':14s} {'positions':>9s} {'before':>8s} {'evenly spread':>14s} {'random median':>14s} "
          f"{'random worst':>13s} {'failed':>7s}")
    for r in rows:
        print(f"{r.serial:14s} {r.size:9d} {r.before_mg:8.3f} {r.structured_mg:14.4f} {r.random_median_mg:14.4f} "
              f"{r.random_max_mg:13.4f} {r.failed:7d}")
    print("noise floor (mg): " + ", ".join(f"{k} {v:.4f}" for k, v in floors.items())
          + "; the full set is scored on its own poses")
    if args.figure is not None:
        print(f"figure → {args.figure}")
    return 0


def _check_figure_path(path: Path) -> None:
    from accelcal_rig.report.figures import pyplot

    pyplot()  # a missing extra is a one-line error before any work
    if not path.parent.is_dir():
        raise ConfigError(f"{path}: folder {path.parent} does not exist")
