"""The report's figures, standing in for the paper's Fig. 6, 7, 10 and 11 and showing the soaks.

matplotlib is an optional extra (`pip install 'accelcal-rig[report]'`); it is drawn off-screen (Agg).
Each function writes one PNG and returns its path.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from accelcal_rig.core.extras import install_hint
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.durable import write_atomically
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.sfem import PARAMETER_NAMES, correct, distort, norm_only_gauge
from accelcal_rig.report.campaign_data import CampaignData

if TYPE_CHECKING:
    from matplotlib.figure import Figure

DPI = 100
#: How each parameter's change is shown: (label, scale from the model's unit).
PARAMETER_DISPLAY = {
    "bias": ("Δ bias {axis} (mg)", 1e3),
    "scale": ("Δ scale {axis} (ppm)", 1e6),
    "nonorth": ("Δ non-orthogonality {axis} (µrad)", 1e6),
    "misalign": ("Δ misalignment {axis} (µrad)", 1e6),
}


def pyplot():  # noqa: ANN201 - matplotlib's module
    """matplotlib.pyplot on the off-screen backend, or a one-line error saying how to install it."""
    try:
        import matplotlib
    except ImportError:
        raise ConfigError(f"rig report needs matplotlib: {install_hint('report')}") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(figure: Figure, path: Path) -> Path:
    """Write the figure as PNG, replacing any file at `path` whole."""
    image = io.BytesIO()
    figure.savefig(image, format="png", dpi=DPI, bbox_inches="tight")
    pyplot().close(figure)
    write_atomically(path, image.getvalue(), "a figure")
    return path


def _temperature_colours(data: CampaignData):  # noqa: ANN202 - (colormap, norm)
    plt = pyplot()
    setpoints = [float(s) for s in data.status.get("setpoints_c", [])]  # planned: soaks may have no poses
    norm = plt.Normalize(min(setpoints, default=0.0) - 1e-9, max(setpoints, default=1.0) + 1e-9)
    return plt.get_cmap("coolwarm"), norm


def norm_deviation(data: CampaignData, path: Path) -> Path:
    """Fig. 6: |g| − 1 at every pose of every setpoint, raw (top) and compensated (bottom), per DUT."""
    plt = pyplot()
    cmap, norm = _temperature_colours(data)
    serials = list(data.duts)
    figure, axes = plt.subplots(2, len(serials), figsize=(3.6 * len(serials) + 1, 6.4), squeeze=False,
                                sharex=True, constrained_layout=True)
    for column, serial in enumerate(serials):
        dut = data.duts[serial]
        gravity = dut.poses.magnitude
        raw = (np.linalg.norm(dut.poses.mean, axis=1) - gravity) * 1e3
        after = (np.linalg.norm(dut.detail.compensated, axis=1) - gravity) * 1e3 if dut.detail else None
        if dut.fit:  # what noise alone spreads a perfectly calibrated pose over
            band = 2 * dut.fit.figures["noise_floor_mg"]
            axes[1, column].axhspan(-band, band, color="0.88", zorder=0, label="±2 × noise floor")
        for setpoint in dict.fromkeys(dut.poses.setpoint_c.tolist()):
            rows = np.flatnonzero(dut.poses.setpoint_c == setpoint)
            rows = rows[np.argsort(dut.pose_numbers[rows], kind="stable")]  # by number, whatever the order visited
            colour = cmap(norm(setpoint))
            axes[0, column].plot(dut.pose_numbers[rows], raw[rows], "o-", ms=3, lw=0.8, color=colour)
            if after is not None:
                axes[1, column].plot(dut.pose_numbers[rows], after[rows], "o-", ms=3, lw=0.8, color=colour)
        title = serial
        if dut.fit:
            title += f"\nRMSE {dut.fit.figures['rmse_before_mg']:.2f} → {dut.fit.figures['rmse_after_mg']:.4f} mg in-sample"
            axes[1, column].legend(fontsize=7, loc="upper right")
        axes[0, column].set_title(title, fontsize=9)
        axes[1, column].set_xlabel("pose")
        if after is None:
            axes[1, column].text(0.5, 0.5, "no fit", ha="center", transform=axes[1, column].transAxes)
    axes[0, 0].set_ylabel("|g| − g before (mg)")
    axes[1, 0].set_ylabel("|g| − g after (mg)")
    figure.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes, label="setpoint (°C)", shrink=0.8)
    figure.suptitle("Norm of gravity at each calibration pose, before and after calibration (paper Fig. 6); g: "
                    + gravity_used(data.gravity_m_s2))
    return save(figure, path)


def gravity_used(gravity_m_s2: float) -> str:
    """Which gravity |g| is compared with: the site's as the rig config states it, or the standard value in its
    place (said so: the figure then shows the site's difference from it too)."""
    if gravity_m_s2 == STANDARD_GRAVITY_M_S2:
        return f"the standard {STANDARD_GRAVITY_M_S2} m/s² (the site's was not stated)"
    return f"the site's {gravity_m_s2:.6g} m/s²"


def _sphere_grid(n: int = 24) -> np.ndarray:
    """Points (n, n, 3) on the unit sphere, for wireframes."""
    azimuth, polar = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n))
    return np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=-1)


def _exaggerated(accel_g: np.ndarray, reference_g: np.ndarray | None, gain: float, gravity_g: float = 1.0) -> np.ndarray:
    """Readings with their error magnified `gain` times so millig errors show: the whole deviation from
    the reference direction when there is one, else only the radial deviation from the site's gravity
    (drawn on the unit sphere)."""
    if reference_g is not None:
        return (reference_g + gain * (accel_g - reference_g)) / gravity_g
    norm = np.linalg.norm(accel_g, axis=-1, keepdims=True)
    return accel_g / norm * (1.0 + gain * (norm - gravity_g) / gravity_g)


def ellipsoid(data: CampaignData, path: Path) -> Path:
    """Fig. 7: raw readings on their ellipsoid and compensated readings on the unit sphere, the error
    magnified by the same factor in both panels (the deviation from the turntable's reference direction in
    reference mode; the radial deviation from 1 g in norm-only mode, which has no reference)."""
    plt = pyplot()
    cmap, norm = _temperature_colours(data)
    fitted = [s for s, d in data.duts.items() if d.fit is not None]
    rows = max((len(fitted) + 1) // 2, 1)
    figure = plt.figure(figsize=(16, 4.2 * rows), constrained_layout=True)
    sphere = _sphere_grid()
    with_reference = data.options is not None and data.options.mode == "reference"

    def error_of(serial: str) -> np.ndarray:
        poses = data.duts[serial].poses
        return (poses.mean - poses.reference if with_reference
                else np.linalg.norm(poses.mean, axis=1) - poses.magnitude)

    # One magnification for every panel, so the DUTs compare at a glance.
    gain = 0.3 / max([float(np.max(np.abs(error_of(s)))) for s in fitted] + [1e-9])
    panels = []
    for index, serial in enumerate(fitted):
        dut = data.duts[serial]
        assert dut.fit is not None
        assert dut.detail is not None
        raw, compensated = dut.poses.mean, dut.detail.compensated
        reference = dut.poses.reference if with_reference else None
        middle = len(dut.detail.fits) // 2
        surface = _exaggerated(distort(sphere, dut.detail.fits[middle].parameters), sphere if with_reference else None,
                               gain)
        colours = cmap(norm(dut.poses.setpoint_c))
        for column, (points, mesh, title) in enumerate([
                (raw, surface, f"{serial} raw; ellipsoid at {dut.detail.setpoints_c[middle]:g} °C"),
                (compensated, sphere, f"{serial} calibrated; unit sphere")]):
            axis = figure.add_subplot(rows, 4, 2 * index + column + 1, projection="3d")
            axis.plot_wireframe(*np.moveaxis(mesh, -1, 0), color="0.75", lw=0.4)
            axis.scatter(*_exaggerated(points, reference, gain, dut.poses.magnitude).T, c=colours, s=12,
                         depthshade=False)
            axis.set_title(title, fontsize=9)
            axis.set_box_aspect((1, 1, 1))
            for ticks, label, name in ((axis.set_xticks, axis.set_xlabel, "x"), (axis.set_yticks, axis.set_ylabel, "y"),
                                       (axis.set_zticks, axis.set_zlabel, "z")):
                ticks([-1, 0, 1])
                label(f"{name} (g)", fontsize=8, labelpad=-8)
            axis.tick_params(labelsize=7, pad=-2)
            panels.append(axis)
    if not fitted:
        figure.text(0.5, 0.5, f"no fit: {data.no_fit_reason}", ha="center")
    else:
        figure.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=panels, label="setpoint (°C)", shrink=0.6)
    figure.suptitle(f"Raw ellipsoid and calibrated sphere (paper Fig. 7): every pose's error magnified {gain:,.0f} "
                    "times in every panel")
    return save(figure, path)


def parameters(data: CampaignData, path: Path) -> Path:
    """Fig. 10: each Eq. 1 parameter at each setpoint (±1σ) and its polynomial over temperature, per DUT,
    as the change from the polynomial's value mid-range (DUTs differ far more from each other than over
    temperature); the simulated truth as crosses in a dry run."""
    plt = pyplot()
    figure, axes = plt.subplots(4, 3, figsize=(12, 11), constrained_layout=True)
    colours = plt.get_cmap("tab10")
    for index, (serial, dut) in enumerate(data.duts.items()):
        if dut.fit is None or dut.detail is None:
            continue
        fit, detail, colour = dut.fit, dut.detail, colours(index % 10)
        estimates = np.array([f.parameters for f in detail.fits])
        sigmas = np.array([f.sigma for f in detail.fits])
        dense = np.linspace(*fit.thermal.domain_c, 200)
        curve = fit.thermal.parameters_at(dense, "extrapolate")
        middle = fit.thermal.parameters_at(0.5 * sum(fit.thermal.domain_c), "extrapolate")
        truth = dut.truth_by_setpoint
        if truth is not None and data.options is not None and data.options.mode == "norm-only":
            truth = norm_only_gauge(truth)
        for k, name in enumerate(PARAMETER_NAMES):
            axis = axes[k // 3, k % 3]
            group, axis_name = name.split("_")[0], name.split("_")[1]
            label, scale = PARAMETER_DISPLAY[group]
            axis.errorbar(detail.temperatures_c, (estimates[:, k] - middle[k]) * scale, yerr=sigmas[:, k] * scale,
                          fmt="o", ms=3, color=colour, label=serial if k == 0 else None)
            axis.plot(dense, (curve[:, k] - middle[k]) * scale, "-", lw=1, color=colour)
            if truth is not None:
                axis.plot(detail.temperatures_c, (truth[:, k] - middle[k]) * scale, "x", ms=5, color="k",
                          label="simulated truth" if k == 0 and index == 0 else None)
            axis.set_title(label.format(axis=axis_name), fontsize=9)
            axis.tick_params(labelsize=8)
    for axis in axes[-1]:
        axis.set_xlabel("sensor temperature (°C)")
    if any(d.fit for d in data.duts.values()):
        axes[0, 0].legend(fontsize=7)
    figure.suptitle(f"Change of each error parameter over temperature from its mid-range value, with the "
                    f"degree-{data.options.degree if data.options else '?'} polynomials (paper Fig. 10)")
    return save(figure, path)


def drift_limit_mg(data: CampaignData) -> float | None:
    """The procedure's limit on the drawn channel's verification drift (max − min), in mg, where it states one."""
    for dut in data.duts.values():
        limits = data.acceptance.channels.get(dut.poses.channel)
        if limits is not None and "max_drift_mg" in limits.figure_limits():
            return limits.figure_limits()["max_drift_mg"]
    return None


def drift(data: CampaignData, path: Path) -> Path:
    """Fig. 11: zero-g offset per axis over temperature, before compensation (the fitted raw bias, mg) and
    after (what the polynomial model makes of that raw zero-g reading, µg), each relative to its mean; after
    it, the verification poses' residual offsets (hollow) and the acceptance limit's band. A polynomial that
    interpolates its temperatures has no drift after to show: the panel says so instead of plotting zeros."""
    plt = pyplot()
    figure, axes = plt.subplots(2, 3, figsize=(12, 7), sharex=True, constrained_layout=True)
    colours = plt.get_cmap("tab10")
    interpolated = []
    for index, (serial, dut) in enumerate(data.duts.items()):
        if dut.fit is None or dut.detail is None:
            continue
        fit, detail, colour = dut.fit, dut.detail, colours(index % 10)
        bias = np.array([f.parameters[0:3] for f in detail.fits])
        after = correct(bias, fit.thermal.parameters_at(detail.temperatures_c, "extrapolate"))
        powers = min(fit.thermal.degree, len(detail.fits) - 1) + 1
        verification = fit.figures.get("verification")
        for axis_index in range(3):
            axes[0, axis_index].plot(detail.temperatures_c, (bias[:, axis_index] - bias[:, axis_index].mean()) * 1e3,
                                     "o-", ms=3, color=colour, label=serial if axis_index == 0 else None)
            if len(detail.fits) > powers:
                axes[1, axis_index].plot(detail.temperatures_c,
                                         (after[:, axis_index] - after[:, axis_index].mean()) * 1e6, "o-", ms=3,
                                         color=colour)
            if verification is not None:
                rows = verification["by_setpoint"]
                offsets = np.array([r["offset_mg"][axis_index] for r in rows]) * 1e3
                axes[1, axis_index].plot([r["temperature_c"] for r in rows], offsets - offsets.mean(), "o", ms=5,
                                         mfc="none", color=colour)
        if len(detail.fits) <= powers:
            interpolated.append(f"{serial}: degree {fit.thermal.degree} through {len(detail.fits)} temperatures "
                                "interpolates them: its drift after is 0 by construction, not measured")
    limit = drift_limit_mg(data)
    for axis_index, name in enumerate("xyz"):
        axes[0, axis_index].set_title(f"{name} axis", fontsize=10)
        axes[1, axis_index].set_xlabel("sensor temperature (°C)")
        if limit is not None:  # max − min within the limit: every point inside some band this wide
            axes[1, axis_index].axhspan(-limit * 500, limit * 500, color="0.9", zorder=0)
    axes[0, 0].set_ylabel("before: offset − mean (mg)")
    axes[1, 0].set_ylabel("after: offset − mean (µg)")
    if interpolated:
        axes[1, 1].text(0.5, 0.5, "\n".join(interpolated), ha="center", va="center", fontsize=8, wrap=True,
                        transform=axes[1, 1].transAxes)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    handles += [plt.Line2D([], [], color="0.3", marker="o", ls="-", ms=3),
                plt.Line2D([], [], color="0.3", marker="o", ls="", ms=5, mfc="none")]
    labels += ["calibration setpoints (in-sample)", "verification poses (never fitted)"]
    if limit is not None:
        handles.append(plt.Rectangle((0, 0), 1, 1, color="0.9"))
        labels.append(f"acceptance: max − min ≤ {limit:g} mg")
    figure.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 4), fontsize=8)
    figure.suptitle("Zero-g offset drift per axis before and after thermal compensation (paper Fig. 11)")
    return save(figure, path)


def soak_traces(data: CampaignData, band_c: float, path: Path) -> Path:
    """The chamber air and every DUT through each soak on the campaign clock (top), and each soak's DUT
    temperatures relative to where they settled, against time since the setpoint was reached (bottom)."""
    plt = pyplot()
    cmap, norm = _temperature_colours(data)
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(11, 8), constrained_layout=True)
    for soak in data.soaks:
        hours = soak.t_s / 3600.0
        top.plot(hours, soak.chamber_c, "-", color="k", lw=1.0)
        for column in range(soak.dut_c.shape[1] if soak.dut_c.ndim == 2 else 0):
            top.plot(hours, soak.dut_c[:, column], "-", lw=0.7, color=cmap(norm(soak.setpoint_c)))
        if np.isfinite(soak.t_stable_s):
            top.axvline(soak.t_stable_s / 3600.0, color="0.6", ls=":", lw=0.8)
        if len(soak.t_s) and soak.dut_c.ndim == 2:
            settled = soak.dut_c[-max(1, len(soak.t_s) // 5):].mean(axis=0)
            bottom.plot((soak.t_s - soak.t_reached_s) / 60.0, soak.dut_c - settled, "-", lw=0.7,
                        color=cmap(norm(soak.setpoint_c)))
    for dut in data.duts.values():
        top.plot(dut.poses.t_s / 3600.0, dut.poses.temperature_c, ".", ms=2, color="tab:green")
        if dut.verification is not None and len(dut.verification.t_s):
            top.plot(dut.verification.t_s / 3600.0, dut.verification.temperature_c, "o", ms=3, mfc="none", mew=0.6,
                     color="tab:purple")
    top.plot([], [], "-", color="k", label="chamber air")
    top.plot([], [], ".", color="tab:green", label="DUTs during calibration poses")
    if any(d.verification is not None and len(d.verification.t_s) for d in data.duts.values()):
        top.plot([], [], "o", ms=3, mfc="none", mew=0.6, color="tab:purple", label="DUTs during verification poses")
    top.plot([], [], ":", color="0.6", label="soak criterion met")
    top.legend(fontsize=8)
    top.set_xlabel("campaign time (h)")
    top.set_ylabel("temperature (°C)")
    top.set_title("Soaks: chamber air (black) and each DUT (coloured by setpoint)", fontsize=10)
    for sign in (-1, 1):
        bottom.axhline(sign * band_c / 2, color="0.5", ls="--", lw=0.8)
    bottom.set_ylim(-5 * band_c, 5 * band_c)
    bottom.set_xlabel("time since the chamber reached the setpoint (min)")
    bottom.set_ylabel("DUT − its settled temperature (°C)")
    bottom.set_title(f"Settling of every DUT at every setpoint; dashed: the soak band, {band_c:g} °C wide (max − min "
                     "over the window)", fontsize=10)
    figure.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=[top, bottom], label="setpoint (°C)", shrink=0.6)
    return save(figure, path)


def channel_parameters(data: CampaignData, quantity: str, path: Path) -> Path:
    """Each calibrated channel of `quantity`'s first two kinds of parameter (its model's: a bias and a scale error)
    per axis over temperature: each setpoint's estimate ±1σ and the polynomial through them."""
    plt = pyplot()
    model = model_for_quantity(quantity)
    assert model is not None
    groups = model.parameter_groups[:2]
    figure, axes = plt.subplots(len(groups), 3, figsize=(13, 3.5 * len(groups)), sharex=True, squeeze=False)
    colours = plt.get_cmap("tab10")
    calibrated = [(serial, fitted.fit.calibration) for serial, channels in data.channels.items()
                  for fitted in channels.values() if fitted.model.quantity == quantity]
    for index, (serial, calibration) in enumerate(calibrated):
        colour = colours(index % 10)
        low, high = calibration.validity_c
        curve_t = np.linspace(low, high, 100)
        curve = calibration.polynomial.at(curve_t)
        names = list(calibration.parameter_names)
        setpoints_t = np.array([s.temperature_c for s in calibration.setpoints])
        for row, group in enumerate(groups):
            for column, name in enumerate(group.names[:3]):
                k = names.index(name)
                ax = axes[row, column]
                ax.plot(curve_t, (curve[:, k] + group.offset) * group.factor, color=colour, lw=1.2,
                        label=serial if (row, column) == (0, 0) else None)
                values = np.array([(s.parameters[name] + group.offset) * group.factor for s in calibration.setpoints])
                sigmas = np.array([(s.sigma.get(name) or 0.0) * group.factor for s in calibration.setpoints])
                ax.errorbar(setpoints_t, values, yerr=sigmas, fmt="o", ms=4, color=colour, capsize=3)
    for row, group in enumerate(groups):
        for column, axis in enumerate(group.columns[:3]):
            axes[0, column].set_title(f"{model.sensor} {axis}")
            axes[row, column].set_ylabel(f"{group.label} {axis} ({group.unit})")
            axes[row, column].grid(alpha=0.3)
            axes[-1, column].set_xlabel("sensor temperature (°C)")
    if calibrated:
        axes[0, 0].legend(fontsize=8)
    figure.suptitle(f"{model.sensor.capitalize()} {groups[0].label} and {groups[1].label} over temperature: each "
                    "setpoint's fit (±1σ) and the polynomial")
    figure.tight_layout()
    return save(figure, path)


#: σ(τ) of flicker noise of bias instability B on its flat part, as a factor of B (fit/allan.py).
_FLICKER_FLOOR = float(np.sqrt(2.0 * np.log(2.0) / np.pi))
def allan(data: CampaignData, path: Path) -> Path:
    """The overlapping Allan deviation of each DUT's still record per axis, log-log, both sensors; the fitted
    random walk marked where it is read off (σ(1 s) = N on the −½ slope, dashed) and the bias instability at its
    averaging time (0.664·B, a triangle)."""
    plt = pyplot()
    channels = list(dict.fromkeys(n.quantity for curves in data.noise.values() for n in curves))
    figure, axes = plt.subplots(1, max(len(channels), 1), figsize=(7 * max(len(channels), 1), 5.5), squeeze=False)
    colours = plt.get_cmap("tab10")
    styles = ("-", "--", ":")
    for column, channel in enumerate(channels):
        model = model_for_quantity(channel)
        assert model is not None and model.noise is not None
        quoted = model.noise
        title, unit, factor = model.sensor, quoted.instability_unit, quoted.instability_factor
        walk, walk_factor = quoted.random_walk, 1.0 / quoted.random_walk_factor
        instability, instability_factor = quoted.instability, 1.0 / quoted.instability_factor
        ax = axes[0, column]
        for index, (serial, records) in enumerate(data.noise.items()):
            colour = colours(index % 10)
            for record in records:
                if record.quantity != channel:
                    continue
                for k, (axis, curve) in enumerate(zip("xyz", record.curves)):
                    ax.loglog(curve.tau_s, curve.deviation * factor, styles[k], color=colour, lw=1.0,
                              label=f"{serial} {axis}")
                    walks = record.figures.get(walk)
                    if isinstance(walks, list) and k < len(walks):
                        n = walks[k]["value"] * walk_factor
                        tau = curve.tau_s[[0, -1]]
                        ax.loglog(tau, n / np.sqrt(tau) * factor, color=colour, lw=0.6, alpha=0.5, ls=(0, (4, 3)))
                        ax.plot([1.0], [n * factor], "o", color=colour, ms=4)
                    bis = record.figures.get(instability)
                    if isinstance(bis, list) and k < len(bis) and bis[k]["value"] > 0:
                        ax.plot([bis[k]["tau_s"]], [_FLICKER_FLOOR * bis[k]["value"] * instability_factor * factor], "^",
                                color=colour, ms=6)
        setpoint = next((r.setpoint_c for records in data.noise.values() for r in records), None)
        ax.set_title(f"{title}: overlapping Allan deviation" + (f" at {setpoint:g} °C" if setpoint is not None else ""))
        ax.set_xlabel("averaging time τ (s)")
        ax.set_ylabel(f"σ(τ) ({unit})")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6, ncol=2)
    figure.suptitle("Allan deviation of the still record per axis: dots, the random walk N at τ = 1 s (dashed, N/√τ); "
                    "triangles, 0.664 × the bias instability where it is read")
    figure.tight_layout()
    return save(figure, path)
