"""Figures of `rig analyze`: positions (paper Fig. 8), tilt, free cool-down (paper Fig. 11)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.analysis.cooldown import CooldownResult
from accelcal_rig.analysis.positions import SizeSummary
from accelcal_rig.report.figures import pyplot, save


def positions_figure(rows: list[SizeSummary], floors_mg: dict[str, float], mode: str, path: Path) -> Path:
    """RMSE of |g| on held-out poses against the number of positions: before calibration on the left
    axis, after on the right (log), the median and worst of the random subsets and the structured one."""
    plt = pyplot()
    figure, left = plt.subplots(figsize=(9, 5.5), constrained_layout=True)
    right = left.twinx()
    colours = plt.get_cmap("tab10")
    for index, serial in enumerate(dict.fromkeys(r.serial for r in rows)):
        mine = sorted((r for r in rows if r.serial == serial), key=lambda r: r.size)
        sizes = np.array([r.size for r in mine])
        colour = colours(index % 10)
        left.plot(sizes, [r.before_mg for r in mine], ":", color=colour, lw=1)
        right.plot(sizes, [r.random_median_mg for r in mine], "o-", ms=3, color=colour, label=f"{serial} random (median)")
        right.fill_between(sizes, [r.random_median_mg for r in mine], [r.random_max_mg for r in mine], color=colour,
                           alpha=0.12, lw=0)
        right.plot(sizes, [r.structured_mg for r in mine], "s--", ms=3, color=colour, lw=0.8,
                   label=f"{serial} evenly spread")
        right.axhline(floors_mg[serial], color=colour, lw=0.6, ls="-.")
    left.set_xscale("log")
    right.set_yscale("log")
    left.set_xlabel("number of positions in the fit")
    left.set_ylabel("RMSE of |g| before calibration (mg, dotted)")
    right.set_ylabel("RMSE of |g| after calibration, on the poses left out (mg)")
    ticks = sorted({r.size for r in rows})
    left.set_xticks(ticks)
    left.set_xticklabels([str(t) for t in ticks], fontsize=7, rotation=45)
    right.legend(fontsize=7, loc="upper right")
    figure.suptitle(f"How many positions a calibration needs ({mode} fit; shaded: median to worst of the random "
                    "subsets; dash-dot: noise floor) — paper Fig. 8")
    return save(figure, path)


def cooldown_figure(results: list[CooldownResult], path: Path) -> Path:
    """Paper Fig. 11: each DUT's temperature during the cool-down (top), and each axis's output relative to
    its value at the end (the mean of the last tenth), before (left) and after (right) compensation."""
    plt = pyplot()
    figure, axes = plt.subplots(4, 2, figsize=(12, 11), sharex=True, constrained_layout=True)
    colours = plt.get_cmap("tab10")
    for index, r in enumerate(results):
        colour = colours(index % 10)
        minutes = (r.t_s - r.t_s[0]) / 60.0
        for column in range(2):
            axes[0, column].plot(minutes, r.temperature_c, "-", color=colour, lw=1, label=r.serial)
        for axis in range(3):
            for column, (values, coefficients) in enumerate(((r.before_g, r.coefficient_before_ug_per_k),
                                                             (r.after_g, r.coefficient_after_ug_per_k))):
                final = values[-max(len(values) // 10, 1):, axis].mean()
                axes[axis + 1, column].plot(minutes, (values[:, axis] - final) * 1e3, "-", color=colour,
                                            lw=1, label=f"{r.serial}: {coefficients[axis]:+.1f} µg/K")
    for column, title in enumerate(("before compensation", "after compensation")):
        axes[0, column].set_title(f"{title}", fontsize=10)
        axes[0, column].set_ylabel("DUT temperature (°C)")
        for axis, name in enumerate("xyz"):
            axes[axis + 1, column].set_ylabel(f"{name} output − its final value (mg)")
            axes[axis + 1, column].legend(fontsize=7, title="slope over temperature", title_fontsize=7)
        axes[3, column].set_xlabel("time since the chamber was let go (min)")
    axes[0, 0].legend(fontsize=7)
    figure.suptitle("Free cool-down: output per axis before and after thermal compensation (paper Fig. 11)")
    return save(figure, path)
