"""`rig report`: one self-contained HTML page and its PNG figures in a folder, readable with no network.

No scripts, no web fonts, no remote anything: inline CSS and `<img>` tags pointing at files beside it.
"""

from __future__ import annotations

import html
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.core.formatting import format_duration, format_fixed
from accelcal_rig.core.units import gravity_statement
from accelcal_rig.durable import write_text_atomically
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.campaign_fit import FitOptions
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.report import figures
from accelcal_rig.report.campaign_data import DRAWN_QUANTITY, CampaignData, read_campaign_data
from accelcal_rig.store.records import utc_now

STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
th { background: #f0f0f0; } td.text, th.text { text-align: left; } td.unbroken { white-space: nowrap; }
tr.warning td { background: #fff6d5; } tr.error td { background: #fde0e0; } tr.total td { font-weight: bold; }
tr.conditional td { background: #ffe2a8; }
img { max-width: 100%; border: 1px solid #eee; } .note { color: #555; font-size: 0.9em; }
.state-done { color: #106010; } .state-aborted, .state-running { color: #a01010; }
"""

FIGURES = {
    "norm_deviation": "norm_deviation.png",
    "ellipsoid": "ellipsoid.png",
    "parameters": "parameters.png",
    "drift": "drift.png",
    "soaks": "soak_traces.png",
}
#: Drawn only where the campaign has them: a calibrated gyroscope, a still noise record.
GYRO_FIGURES = {"allan": "allan_deviation.png"}
#: A verdict's row style: a failed DUT highlighted, a CONDITIONAL one (inside a guard band) in amber.
_VERDICT_ROWS = {"FAIL": "warning", "CONDITIONAL": "conditional"}


def _e(value: object) -> str:
    return html.escape(str(value))


def _table(header: list[str] | None, rows: Sequence[Sequence[object]], text_columns: int = 1,
           row_classes: list[str] | None = None, unbroken: tuple[int, ...] = ()) -> str:
    """`header` None: no header row (a table of named facts); `unbroken`: columns never wrapped inside a value
    (timestamps)."""
    def cell(tag: str, index: int, value: object) -> str:
        classes = " ".join(c for c, on in (("text", index < text_columns), ("unbroken", index in unbroken)) if on)
        css = f' class="{classes}"' if classes else ""
        return f"<{tag}{css}>{_e(value)}</{tag}>"

    head = "" if header is None else "<tr>" + "".join(cell("th", i, h) for i, h in enumerate(header)) + "</tr>"
    body = []
    for r, row in enumerate(rows):
        css = f' class="{row_classes[r]}"' if row_classes and row_classes[r] else ""
        body.append(f"<tr{css}>" + "".join(cell("td", i, v) for i, v in enumerate(row)) + "</tr>")
    return f"<table>{head}{''.join(body)}</table>"


def _figure(name: str, caption: str) -> str:
    return _image(FIGURES.get(name) or GYRO_FIGURES[name], caption)


def _image(file: str, caption: str) -> str:
    return f'<figure><img src="figures/{file}" alt="{_e(caption)}"><figcaption class="note">{_e(caption)}' \
           "</figcaption></figure>"


def write_report(campaign: Path, output: Path) -> Path:
    """Write `output/index.html` and `output/figures/*.png` for a campaign file; return the HTML path."""
    data = read_campaign_data(campaign)
    folder = output / "figures"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"{folder}: cannot make the report's folder: {exc.strerror}") from None
    figures.norm_deviation(data, folder / FIGURES["norm_deviation"])
    figures.ellipsoid(data, folder / FIGURES["ellipsoid"])
    figures.parameters(data, folder / FIGURES["parameters"])
    figures.drift(data, folder / FIGURES["drift"])
    figures.soak_traces(data, data.soak_band_c, folder / FIGURES["soaks"])
    for quantity in _other_quantities(data):
        figures.channel_parameters(data, quantity, folder / _parameters_figure(quantity))
    if data.noise:
        figures.allan(data, folder / GYRO_FIGURES["allan"])
    page = output / "index.html"
    write_text_atomically(page, _page(data), "the report")
    return page


def _page(data: CampaignData) -> str:
    status = data.status
    title = f"Calibration campaign {status.get('procedure', data.path.name)}"
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{_e(title)}</title>",
             f"<style>{STYLE}</style></head><body>", f"<h1>{_e(title)}</h1>",
             f"<p class='note'>{_e(data.path)} — report by accelcal-rig {__version__} at {_e(utc_now())}</p>"]
    parts += _summary(data)
    fitted = any(d.fit for d in data.duts.values())
    if not fitted:
        parts.append(f"<p><b>No calibration:</b> {_e(data.no_fit_reason)}. The figures below show what was "
                     "measured.</p>")
    parts += ["<h2>Norm of gravity per pose</h2>",
              _figure("norm_deviation", "|g| − 1 at each pose, every setpoint coloured by temperature: raw readings "
                                        "(top) and compensated with the thermal model (bottom). Paper Fig. 6.")]
    parts += ["<h2>Raw ellipsoid and calibrated sphere</h2>",
              _figure("ellipsoid", "Per-pose mean readings with their error magnified by the same factor in both "
                                   "panels: the deviation from the turntable's reference direction (reference "
                                   "mode) or from 1 g (norm-only mode). Paper Fig. 7.")]
    parts += ["<h2>Uncertainty budget</h2>", _uncertainty_table(data)]
    parts += ["<h2>RMSE of |g| per setpoint</h2>", _rmse_table(data)]
    parts += ["<h2>Error parameters at the reference temperature</h2>", _parameter_table(data)]
    parts += ["<h2>Error parameters over temperature</h2>",
              _figure("parameters", "Each Eq. 1 parameter fitted at each setpoint (±1σ) and its polynomial over "
                                    "the sensor temperature (Eq. 8); crosses: the simulated truth (dry runs). "
                                    "Paper Fig. 10.")]
    parts += ["<h2>Offset drift before and after compensation</h2>",
              _figure("drift", "Zero-g offset per axis over temperature: the raw bias (top), and what the "
                               "compensation makes of the raw zero-g reading (bottom). Paper Fig. 11."),
              _drift_table(data)]
    parts += _channels_section(data)
    if data.noise:
        parts += ["<h2>Noise: Allan deviation</h2>",
                  _figure("allan", "Overlapping Allan deviation of each DUT's still record per axis, log-log, both "
                                   "sensors; dots: the fitted random walk N at τ = 1 s (the dashed line N/√τ through "
                                   "it); triangles: 0.664 × the bias instability B at the averaging time it is read "
                                   "at (none where B is zero)."),
                  _noise_table(data)]
    parts += ["<h2>Soaks</h2>", _figure("soaks", "Temperature traces of every soak."), _soak_table(data)]
    if any(d.fit is not None and "truth_error" in d.fit.figures for d in data.duts.values()):
        parts += ["<h2>Against the simulated truth</h2>", _truth_table(data)]
    parts += ["<h2>Event log</h2>", _event_table(data), "</body></html>"]
    return "\n".join(parts)


def _summary(data: CampaignData) -> list[str]:
    s = data.status
    state = str(s.get("state", "?"))
    rows = [
        ["state", f"{state}" + (f": {s['abort_reason']}" if s.get("abort_reason") else "")],
        ["procedure", f"{s.get('procedure')} ({data.procedure_path})"],
        ["rig", data.rig_name + (" — simulated (dry run)" if s.get("dry_run") else "")],
        ["poses", f"{s.get('poses_done')} of {s.get('poses_total')} × {len(data.duts)} DUTs × "
                  f"{s.get('samples_per_pose')} samples"],
        ["setpoints (°C)", ", ".join(f"{t + 0.0:g}" for t in s.get("setpoints_c", []))],
        ["started / finished", f"{s.get('started')} / {s.get('finished') or '—'}"],
        ["campaign time", format_duration(float(data.pose_t_s.max())) if len(data.pose_t_s) else "—"],
        ["fit", _fit_description(data.options)],
        ["gravity", gravity_statement(data.gravity_m_s2)],
        ["integrity", s.get("integrity", "?")],
    ]
    out = ["<h2>Campaign</h2>", _table(None, rows, text_columns=2)]
    sensors, verified, classes = [], [], []
    for serial, dut in data.duts.items():
        if dut.fit is None:
            sensors.append([serial, "—", "—", "—", "—", "—", "no fit"])
            continue
        m = dut.fit.figures
        sensors.append([serial, f"{m['rmse_before_mg']:.3f}", f"{m['noise_floor_mg']:.4f}",
                        f"{m['expected_fit_rmse_mg']:.4f}", f"{m['rmse_after_mg']:.4f}",
                        " / ".join(f"{v * 1e3:.1f}" for v in m["drift_after_mg"]),
                        "; ".join(dut.fit.thermal.warnings) or "—"])
        v = m.get("verification")
        verdict = dut.judgement.verdict if dut.judgement else "—"
        reasons = "; ".join(dut.judgement.reasons) if dut.judgement else ""
        verified.append([serial, verdict, reasons, *(["—"] * 6 if v is None else [
            v["n_poses"], f"{v['rmse_mg']:.4f}", f"{v['rmse_mg'] / v['noise_floor_mg']:.2f}",
            f"{v['max_axis_error_mg']:.4f}", f"{v['max_tilt_error_deg']:.4f}",
            " / ".join(f"{d * 1e3:.1f}" for d in v["drift_mg"])])])
        classes.append(_VERDICT_ROWS.get(verdict, ""))
    out += ["<h2>Calibration: verification (poses the fit never saw)</h2>",
            _table(["DUT", "verdict", "reasons", "poses", "|g| RMSE (mg)", "÷ noise floor", "largest axis error (mg)",
                    "largest tilt error (°)", "residual drift x/y/z (µg)"], verified, text_columns=3,
                   row_classes=classes),
            "<p class='note'>The figures that say how good the calibration is: each verification pose compensated at "
            "its own temperature as the calibration file would, against the turntable's gravity. A pose the fit "
            "never saw cannot beat its own noise: |g| RMSE ÷ noise floor is at least about 1.</p>"
            if any(row[3] != "—" for row in verified) else
            "<p><b>No verification poses:</b> every figure below is in-sample (on the poses fitted).</p>",
            "<h2>Calibration: in-sample (the poses fitted)</h2>",
            _table(["DUT", "|g| RMSE before (mg)", "noise floor (mg)", "expected fit (mg)", "after (mg)",
                    "drift after x/y/z (µg)", "warnings"], sensors),
            "<p class='note'>In-sample: every calibration pose compensated with the polynomial model at its own "
            "temperature — the fit has seen these poses, so they reach the expected fit RMSE, below the noise "
            "floor (the RMSE the per-pose standard errors alone leave with the true parameters).</p>"]
    left = sorted({(channel, why) for channels in data.not_calibrated.values() for channel, why in channels.items()})
    out += [f"<p><b>Not calibrated:</b> the {_e(channel)} channel of {len(_having(data, channel))} DUTs "
            f"({_e(', '.join(_having(data, channel)))}): {_e(why)}; its raw codes are in the campaign file "
            f"(duts/&lt;serial&gt;/{_e(channel)}/).</p>" for channel, why in left]
    return out


def _other_quantities(data: CampaignData) -> list[str]:
    """The calibrated quantities besides the one the report's own figures draw (each gets its parameters' figure)."""
    return list(dict.fromkeys(c.model.quantity for channels in data.channels.values() for c in channels.values()
                              if c.model.quantity != DRAWN_QUANTITY))


def _parameters_figure(quantity: str) -> str:
    return f"{quantity.replace(' ', '_')}_parameters.png"


def _channels_section(data: CampaignData) -> list[str]:
    """Every calibrated channel of a quantity the report's sections above do not draw in detail, a table per
    quantity: each DUT's verdict and its model's figures (in-sample and on the records the fit never saw), and its
    parameters over temperature."""
    parts = []
    quantities = list(dict.fromkeys(c.model.quantity for channels in data.channels.values() for c in channels.values()
                                    if c.model.quantity != DRAWN_QUANTITY))
    for quantity in quantities:
        fitted = [(serial, name, c) for serial, channels in data.channels.items() for name, c in channels.items()
                  if c.model.quantity == quantity]
        model = fitted[0][2].model
        rows, classes = [], []
        for serial, name, c in fitted:
            rows.append([serial, name, c.judgement.verdict, "; ".join(c.judgement.reasons),
                         *(f.text(c.fit.figures) for f in model.figures)])
            classes.append(_VERDICT_ROWS.get(c.judgement.verdict, ""))
        parts += [f"<h2>Calibration of every {_e(model.sensor)} ({_e(quantity)})</h2>",
                  _table(["DUT", "channel", "verdict", "reasons", *(f"{f.label} ({f.unit})" for f in model.figures)],
                         rows, text_columns=4, row_classes=classes),
                  "<p class='note'>Fitted from the campaign for this report with the options it records, as rig fit "
                  "does; a per-axis figure shows its largest axis; verification figures are on records the fit never "
                  "saw.</p>"]
        parts += [f"<h2>{_e(model.sensor.capitalize())} parameters over temperature</h2>",
                  _image(_parameters_figure(quantity),
                         f"Each {model.sensor}'s {model.parameter_groups[0].label} and "
                         f"{model.parameter_groups[1].label} per axis fitted at each setpoint (±1σ) and its "
                         "polynomial over the sensor temperature.")]
    return parts


def _noise_table(data: CampaignData) -> str:
    """Per DUT and channel: the random walk and bias instability per axis with their 68 % intervals."""
    rows = []
    for serial, records in data.noise.items():
        for record in records:
            model = model_for_quantity(record.quantity)
            quoted = model.noise if model is not None else None
            if quoted is None:
                continue
            keys = ((quoted.random_walk, f"{quoted.random_walk_label} ({quoted.random_walk_unit})",
                     quoted.random_walk_spec),
                    (quoted.instability, f"bias instability ({quoted.instability_unit})", quoted.instability_spec))
            for key, label, spec in keys:
                values = record.figures.get(key)
                if isinstance(values, list):
                    rows.append([serial, record.channel, label, f"{record.setpoint_c + 0.0:g}",
                                 *(f"{format(e['value'], spec)} [{format(e['low'], spec)}, {format(e['high'], spec)}]"
                                   for e in values)])
    if not rows:
        return ""
    return (_table(["DUT", "channel", "figure", "record at (°C)", "x", "y", "z"], rows, text_columns=3)
            + "<p class='note'>Read off the Allan deviation by a non-negative fit of its white, flicker and random-walk "
              "terms (docs/calibration.md, Noise); [68 % interval].</p>")


def _having(data: CampaignData, channel: str) -> list[str]:
    return [serial for serial, channels in data.not_calibrated.items() if channel in channels]


def _rmse_table(data: CampaignData) -> str:
    """Table 6 of the paper: per setpoint, RMSE before, with the setpoint's own fit, with the polynomials."""
    fitted = {s: d.fit for s, d in data.duts.items() if d.fit is not None}
    if not fitted:
        return "<p>No fit.</p>"
    setpoints = sorted({r["setpoint_c"] for f in fitted.values() for r in f.figures["rmse_by_setpoint"]})
    header = ["setpoint (°C)"] + [f"{serial} {what}" for serial in fitted for what in ("before", "own fit", "polynomial")]
    rows = []
    for setpoint in setpoints:
        row: list[object] = [f"{setpoint:g}"]
        for fit in fitted.values():
            record = next((r for r in fit.figures["rmse_by_setpoint"] if r["setpoint_c"] == setpoint), None)
            row += [f"{record['before_mg']:.3f}", f"{record['measurement_mg']:.4f}", f"{record['polynomial_mg']:.4f}"] \
                if record else ["—"] * 3
        rows.append(row)
    return _table(header, rows) + ("<p class='note'>mg, in-sample (the calibration poses; the verification poses' "
                                   "figures are above). Own fit: the setpoint's LM estimate applied to its poses; "
                                   "polynomial: the thermal model at each pose's temperature. Paper Table 6.</p>")


def _uncertainty_table(data: CampaignData) -> str:
    """Per DUT, each source's standard uncertainty and the expanded one, worst case over the range."""
    rows, classes, notes, budgets = [], [], [], []
    for serial, dut in data.duts.items():
        if dut.fit is None:
            continue
        budget = dut.fit.figures["uncertainty_budget"]
        for name, values in budget["sources_mg"].items():
            rows.append([serial, name.replace("_", " "), *(f"{v * 1e3:.1f}" for v in values)])
            classes.append("")
        rows.append([serial, "combined (k = 1)", *(f"{v * 1e3:.1f}" for v in budget["standard_mg"])])
        rows.append([serial, f"expanded (k = {budget['coverage_factor']:g})", *(f"{v * 1e3:.1f}" for v in budget["expanded_mg"])])
        classes += ["", "total"]
        coverage = dut.fit.figures.get("truth_coverage_k2")
        if coverage is not None:
            notes.append(f"{serial}: {coverage * 100:.1f} % of its verification axis errors against the simulation "
                         "truth lie inside their expanded uncertainty")
        budgets.append(budget)
    if not rows:
        return "<p>No fit.</p>"
    return (_table(["DUT", "source", "x (µg)", "y (µg)", "z (µg)"], rows, text_columns=2, row_classes=classes)
            + f"<p class='note'>Standard uncertainties of a compensated reading, each source's largest over every "
              f"orientation and the calibrated range (GUM; sources uncorrelated): {_e(_reading_of(budgets))}. "
              "Calibration noise and turntable pointing reach the reading through the fitted coefficients.</p>"
            + "".join(f"<p class='note'>{_e(n)} (a dry run; about 95 % is what k = 2 promises).</p>" for n in notes))


def _reading_of(budgets: list[dict]) -> str:
    """The reading the budgets are of, its figures as the range over the DUTs (one DUT's own where there is
    one): a reading averaged like a calibration pose, its temperature read like a pose's."""
    stderr = [value for b in budgets for value in b.get("reading_stderr_mg", [])]
    temperature = [float(b["temperature_u_c"]) for b in budgets if "temperature_u_c" in b]
    if not stderr or not temperature:
        return "; ".join(dict.fromkeys(str(b["reading"]) for b in budgets))
    whose = f" (the range over the {len(budgets)} DUTs)" if len(budgets) > 1 else ""
    return (f"a reading averaged like a calibration pose (standard error {_span(stderr, 4)} mg per axis), its "
            f"temperature read like a pose's (±{_span(temperature, 3)} °C){whose}")


def _span(values: list[float], digits: int) -> str:
    """`0.0123 … 0.0125`, or the one value when all round alike."""
    low, high = format_fixed(min(values), digits), format_fixed(max(values), digits)
    return low if low == high else f"{low} … {high}"


def _parameter_table(data: CampaignData) -> str:
    """Absolute values at the acceptance limits' temperature (else 25 °C, clamped into the range), beside the
    data sheet's range and the procedure's limits."""
    channel = next((dut.poses.channel for dut in data.duts.values()), "")
    drawn = data.acceptance.channels.get(channel)
    limits = drawn.parameters if drawn is not None else None
    at_c = limits.at_c if limits is not None else 25.0
    rows, classes = [], []
    for serial, dut in data.duts.items():
        if dut.fit is None:
            continue
        low, high = dut.fit.thermal.domain_c
        t = min(max(at_c, low), high)
        p = dut.fit.thermal.parameters_at(t, "clamp")
        datasheet = data.zero_g_offset_mg.get(serial)
        bias = np.abs(p[0:3]) * 1e3
        outside = datasheet is not None and bool(np.any(bias > datasheet))
        rows.append([serial, format_fixed(t), *(f"{v:+.3f}" for v in p[0:3] * 1e3), f"±{datasheet:g}" if datasheet else "—",
                     *(f"{v:+.0f}" for v in (p[3:6] - 1.0) * 1e6), *(f"{v:+.3f}" for v in p[6:9] * 1e3)])
        classes.append("warning" if outside else "")
    if not rows:
        return "<p>No fit.</p>"
    stated = ("; the procedure's limits: " + ", ".join(
        f"{name.replace('_', ' ')} {value:g}" for name, value in limits.limits().items()) if limits is not None else "")
    return (_table(["DUT", "at (°C)", "bias x (mg)", "bias y (mg)", "bias z (mg)", "data sheet 0 g offset (mg)",
                    "scale error x (ppm)", "y (ppm)", "z (ppm)", "non-orth. yx (mrad)", "zx (mrad)", "zy (mrad)"],
                   rows, text_columns=1, row_classes=classes)
            + f"<p class='note'>The calibration's parameters themselves (not changes over temperature){_e(stated)}. "
              "A highlighted row has a bias outside its part's data sheet range.</p>")


def _drift_table(data: CampaignData) -> str:
    rows = []
    for serial, dut in data.duts.items():
        if dut.fit is None or dut.detail is None:
            continue
        m = dut.fit.figures
        low, high = m["temperature_range_c"]
        interpolates = len(dut.detail.fits) <= min(dut.fit.thermal.degree, len(dut.detail.fits) - 1) + 1
        after = (["0 by construction (the polynomial interpolates)"] + ["—"] * 2 if interpolates and len(dut.detail.fits) > 1
                 else [f"{v * 1e3:.1f}" for v in m["drift_after_mg"]])
        rows.append([serial, f"{format_fixed(low)} … {format_fixed(high)}", *(f"{v:.3f}" for v in m["drift_before_mg"]),
                     *after])
    return _table(["DUT", "range (°C)", "before x (mg)", "before y (mg)", "before z (mg)", "after x (µg)",
                   "after y (µg)", "after z (µg)"], rows, text_columns=2) if rows else ""


def _soak_table(data: CampaignData) -> str:
    rows, classes = [], []
    for soak in data.soaks:
        to_stable = format_duration(soak.t_stable_s - soak.t_reached_s) if np.isfinite(soak.t_stable_s) else "—"
        settled = soak.dut_c[-1] if soak.dut_c.ndim == 2 and len(soak.dut_c) else []
        rows.append([soak.label, f"{soak.setpoint_c + 0.0:g}", soak.outcome, format_duration(soak.t_reached_s),
                     to_stable, ", ".join(format_fixed(v, 2) for v in settled)])
        classes.append("" if soak.outcome == "stable" else "warning")
    return _table(["soak", "setpoint (°C)", "outcome", "reached at", "stable after", "last DUT readings (°C)"],
                  rows, text_columns=1, row_classes=classes)


def _truth_table(data: CampaignData) -> str:
    rows = []
    for serial, dut in data.duts.items():
        if dut.fit is None or "truth_error" not in dut.fit.figures:
            continue
        z = np.array([r["z"] for r in dut.fit.figures["truth_error"]])
        rows.append([serial, len(z), f"{np.mean(np.abs(z) <= 3) * 100:.1f} %", f"{np.max(np.abs(z)):.2f}",
                     f"{np.sqrt(np.mean(z ** 2)):.2f}"])
    return _table(["DUT", "estimates", "within 3σ of truth", "max |z|", "RMS z"], rows) + (
        "<p class='note'>Every fitted parameter at every setpoint against the simulated sensor's hidden truth; "
        "z = (estimate − truth) / σ. RMS z near 1 means the stated uncertainties are honest.</p>")


def _event_table(data: CampaignData) -> str:
    shown = [e for e in data.events if e.level != "debug"]
    counts = Counter(e.level for e in data.events)
    rows = [[format_duration(e.t_s), e.wall_time, e.level, e.kind, e.message] for e in shown]
    classes = [e.level if e.level in ("warning", "error") else "" for e in shown]
    summary = ", ".join(f"{n} {level}" for level, n in sorted(counts.items()))
    return (f"<p class='note'>{_e(summary)} events; debug events (transitions, each pose) are in the file and "
            "its log, not shown here.</p>" + _table(["campaign time", "wall time", "level", "kind", "message"], rows,
                                                    text_columns=5, row_classes=classes, unbroken=(0, 1)))


def _fit_description(options: FitOptions | None) -> str:
    if options is None:
        return "none: the procedure measures only (see rig analyze)"
    return (f"{options.mode}, {options.free} parameters, polynomial degree {options.degree} "
            f"({options.temperature_model}), {options.out_of_range} outside the calibrated range")
