"""What `rig fit` and `rig fit-recording` print, as lines: a campaign fit's report (`FitOutcome.report`,
as `rig fit --json` prints it) as a table, and a hand-held recording's fit (`RecordingFit.report`, with its
gyro's when it has one)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from accelcal_rig.core.units import gravity_statement
from accelcal_rig.fit.campaign_fit import summary_line


def fit_lines(report: dict[str, Any], output: Path) -> list[str]:
    """The table of every DUT's figures, the one-line summary naming the calibration file, the gravity."""
    return [*fit_table(report), *gyro_table(report), summary_line(report, output),
            f"gravity: {gravity_statement(next(iter(report.values()))['gravity_m_s2'])}"]


def gyro_table(report: dict[str, Any]) -> list[str]:
    """Each calibrated gyroscope's figures: its rate steps before and after, the rates and poses it never saw."""
    gyros = {serial: r["gyro"] for serial, r in report.items() if "gyro" in r}
    if not gyros:
        return []
    lines = [f"{'gyroscope':14s} {'raw':>8s} {'in-sample':>9s} {'verification (never fitted)':^37s}  "
             f"{'U k=2':>7s}  verdict",
             f"{'':14s} {'rms °/s':>8s} {'rms °/s':>9s} {'rms °/s':>8s} {'axis °/s':>9s} {'scale ppm':>9s} "
             f"{'rest °/s':>8s}  {'°/s':>7s}"]
    for serial, g in gyros.items():
        v = g.get("verification") or {}
        cells = [v.get("rmse_dps"), v.get("max_axis_error_dps"), v.get("scale_error_ppm"), v.get("rest_error_dps")]
        shown = [f"{c:{w}.{d}f}" if c is not None else f"{'none':>{w}s}" for c, w, d in
                 zip(cells, (8, 9, 9, 8), (4, 4, 0, 4))]
        lines.append(f"{serial:14s} {g['rmse_before_dps']:8.3f} {g['rmse_after_dps']:9.4f} {' '.join(shown)}  "
                     f"{max(g['expanded_uncertainty_dps']):7.4f}  {g['verdict']}")
        lines += _reasons(g)
    return lines


def fit_table(report: dict[str, Any]) -> list[str]:
    """In-sample figures (the poses fitted) beside verification figures (poses the fit never saw)."""
    lines = [f"{'':14s} {'raw':>8s} {'in-sample (the fitted poses)':^36s}  {'verification (never fitted)':^33s}".rstrip(),
             f"{'sensor':14s} {'|g| mg':>8s} {'floor':>7s} {'expected':>8s} {'|g| mg':>7s} {'drift mg':>10s}  "
             f"{'|g| mg':>7s} {'axis mg':>7s} {'tilt °':>7s} {'drift mg':>9s}  {'U k=2 mg':>8s}  verdict"]
    for serial, r in report.items():
        v = r.get("verification")
        verification = (f"{v['rmse_mg']:7.4f} {v['max_axis_error_mg']:7.4f} {v['max_tilt_error_deg']:7.4f} "
                        f"{max(v['drift_mg']):9.4f}" if v else f"{'none':>7s} {'':7s} {'':7s} {'':9s}")
        lines.append(f"{serial:14s} {r['rmse_before_mg']:8.3f} {r['noise_floor_mg']:7.4f} {r['expected_fit_rmse_mg']:8.4f} "
                     f"{r['rmse_after_mg']:7.4f} {max(r['drift_after_mg']):10.4f}  {verification}  "
                     f"{max(r['expanded_uncertainty_mg']):8.4f}  {r['verdict']}")
        lines += _reasons(r)
        lines += [f"  warning: {warning}" for warning in r["warnings"]]
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
    """The hand-held gyro fit (`HandheldGyroFit.report()`): bias and K with their 1σ, how the moves close."""
    def row(values: list[float], sigmas: list[float], fmt: str) -> str:
        return "  ".join(f"{v:{fmt}} ± {s:.2g}" for v, s in zip(values, sigmas))

    lines = [f"gyro: {gyro['segments']} moves between static intervals, gravity misclosure RMS "
             f"{gyro['residual_rms_before_deg']:.3f}° (K = I, bias from the still) → {gyro['residual_rms_after_deg']:.4f}°; "
             f"rank {gyro['rank']} of 12, condition {gyro['condition']:.3g}",
             f"  bias °/s   {row(gyro['bias_dps'], gyro['bias_sigma_dps'], '+.5f')}",
             f"  scale      {row(gyro['scale'], gyro['scale_sigma'], '.5f')}"]
    lines += [f"  K {'xyz'[i]}        {row(r, s, '+.5f')}" for i, (r, s) in enumerate(zip(gyro["matrix"],
                                                                                            gyro["matrix_sigma"]))]
    lines += [f"  note: {note}" for note in gyro["notes"]]
    return lines


def _reasons(judged: dict[str, Any]) -> list[str]:
    """Why a sensor failed, or which figures its decision rule left inside their guard band."""
    if judged["verdict"] == "FAIL":
        return [f"  fails: {reason}" for reason in judged["verdict_reasons"]]
    if judged["verdict"] == "CONDITIONAL":
        return [f"  conditional: {reason}" for reason in judged["verdict_reasons"] if "conditional" in reason]
    return []
