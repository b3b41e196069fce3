"""What `rig fit` and `rig fit-recording` print, as lines: a campaign fit's report (`FitOutcome.report`,
as `rig fit --json` prints it) as a table per quantity of the figures its channel model names, and a hand-held
recording's fit (`RecordingFit.report`, with its gyro's when it has one)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from accelcal_rig.fit.campaign_fit import summary_line
from accelcal_rig.fit.channel_models import model_for_quantity


def fit_lines(report: dict[str, Any], output: Path) -> list[str]:
    """A table per calibrated quantity of every DUT's figures, the one-line summary naming the calibration file."""
    return [*fit_tables(report), summary_line(report, output)]


def fit_tables(report: dict[str, Any]) -> list[str]:
    """Per quantity, each DUT's channel of it: its model's figures (in-sample first, then on the records the fit
    never saw; a per-axis figure's largest axis), its verdict, why it failed or is conditional, and its fit's
    warnings. The reasons and warnings are the DUT's channel's own."""
    by_quantity: dict[str, list[tuple[str, str, dict[str, Any]]]] = {}
    for serial, dut in report.items():
        for channel, figures in dut["channels"].items():
            by_quantity.setdefault(figures["quantity"], []).append((serial, channel, figures))
    lines: list[str] = []
    for quantity, rows in by_quantity.items():
        model = model_for_quantity(quantity)
        if model is None:
            continue
        widths = [max(len(f.short or f.label), len(f.unit) + 2, 7) for f in model.figures]
        lines.append(f"{model.sensor:14s} {'channel':8s} " + " ".join(f"{f.short or f.label:>{w}s}" for f, w in
                                                                   zip(model.figures, widths)) + "  verdict")
        lines.append(f"{'':14s} {'':8s} " + " ".join(f"{'(' + f.unit + ')':>{w}s}" for f, w in zip(model.figures, widths)))
        for serial, channel, figures in rows:
            lines.append(f"{serial:14s} {channel:8s} " + " ".join(f"{f.text(figures):>{w}s}" for f, w in
                                                               zip(model.figures, widths)) + f"  {figures['verdict']}")
            lines += _reasons(figures)
            lines += [f"  warning: {warning}" for warning in figures.get("warnings", [])]
        lines += [f"{what}: {statement}" for what, statement in model.reference_statements(rows[0][2])]
    return lines


def recording_lines(report: dict[str, Any], source: str, *, threshold_factor: float, init_s: float, output: Path,
                    parameters: str) -> list[str]:
    """The static intervals found (each with |g| before and after), the warnings, and the fit in one line."""
    lines = [f"{len(report['intervals'])} static intervals in {source} ({report['samples']} samples at "
             f"{report['rate_hz']:.4g} Hz; threshold {report['threshold_g2']:.3g} g², {threshold_factor:g} × the "
             f"first {init_s:g} s)",
             f"{'#':>3s} {'start s':>9s} {'end s':>9s} {'samples':>8s} {'mean x, y, z (g)':>29s} {'|g|−1 before':>13s} "
             f"{'after (mg)':>11s}"]
    for k, interval in enumerate(report["intervals"], start=1):
        mean = " ".join(f"{v:+9.5f}" for v in interval["mean_g"])
        lines.append(f"{k:3d} {interval['start_s']:9.2f} {interval['end_s']:9.2f} {interval['samples']:8d} {mean:>29s} "
                     f"{interval['norm_before_mg']:13.3f} {interval['norm_after_mg']:11.4f}")
    lines += [f"warning: {warning}" for warning in report["warnings"]]
    chi2 = "n/a (no degrees of freedom left)" if report["chi2_reduced_before"] is None else (
        f"{report['chi2_reduced_before']:.2f}" + (f" → {report['chi2_reduced']:.2f} with a scatter floor of "
                                                   f"{report['scatter_floor_mg']:.4f} mg" if report["scatter_floor_mg"]
                                                   else ""))
    lines.append(f"calibration → {output}: norm-only, {parameters} parameters, |g| RMSE "
                 f"{report['rmse_before_mg']:.3f} → {report['rmse_after_mg']:.4f} mg (noise floor "
                 f"{report['noise_floor_mg']:.4f} mg) at {report['temperature_c']:.1f} °C; χ²_red {chi2}; outputs in "
                 f"{report['units']}")
    if report.get("gyro"):
        lines += gyro_lines(report["gyro"])
    return lines


def gyro_lines(gyro: dict[str, Any]) -> list[str]:
    """The hand-held gyro fit (`HandheldGyroFit.report()`): bias, K and G with their 1σ, how the moves close;
    what the recording did not determine said so."""
    def row(values: list[float], sigmas: list[float], fmt: str) -> str:
        return "  ".join(f"{v:{fmt}} ± {s:.2g}" for v, s in zip(values, sigmas))

    if gyro["k_determined"]:
        lines = [f"gyro: {gyro['segments']} moves between static intervals, gravity misclosure RMS "
                 f"{gyro['residual_rms_before_deg']:.3f}° (K = I, bias from the still) → "
                 f"{gyro['residual_rms_after_deg']:.4f}°; rank {gyro['rank']}, condition {gyro['condition']:.3g}"]
    else:
        lines = ["gyro: bias from the static intervals; K not determined (nominal sensitivity kept): see the first note"]
    lines.append(f"  bias °/s   {row(gyro['bias_dps'], gyro['bias_sigma_dps'], '+.5f')}")
    if gyro["k_determined"]:
        lines.append(f"  scale      {row(gyro['scale'], gyro['scale_sigma'], '.5f')}")
        lines += [f"  K {'xyz'[i]}        {row(r, s, '+.5f')}" for i, (r, s) in enumerate(zip(gyro["matrix"],
                                                                                                gyro["matrix_sigma"]))]
    if gyro["gsens_fitted"]:
        lines += [f"  G {'xyz'[i]} °/s/g  {row(r, s, '+.5f')}" for i, (r, s) in enumerate(zip(gyro["gsens_dps_per_g"],
                                                                                                 gyro["gsens_sigma"]))]
    lines += [f"  note: {note}" for note in gyro["notes"]]
    return lines


def _reasons(judged: dict[str, Any]) -> list[str]:
    """Why a sensor failed, or which figures its decision rule left inside their guard band."""
    if judged["verdict"] == "FAIL":
        return [f"  fails: {reason}" for reason in judged["verdict_reasons"]]
    if judged["verdict"] == "CONDITIONAL":
        return [f"  conditional: {reason}" for reason in judged["verdict_reasons"] if "conditional" in reason]
    return []
