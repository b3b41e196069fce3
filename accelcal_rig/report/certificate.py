"""`rig certificate`: one calibration certificate per DUT, an HTML page and (with WeasyPrint installed, the
`certificate` extra) its PDF, from a campaign file and the calibration fitted to it.

A certificate states only what the two files hold: the item and its identity as read at preflight, the
campaign and its instruments, the calibration, its verification, its uncertainty budget and its verdict (an
IMU's both sensors: the gyroscope's, and the noise of each, in certificate_gyro.py); fields for the signatures
of who performed and who approved it. A dry run's certificate says on every
page that no physical sensor was calibrated; a partial campaign's says it was partial.
"""

from __future__ import annotations

import html
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.core.units import gravity_statement
from accelcal_rig.durable import clear_dead_temporaries, write_atomically, write_text_atomically
from accelcal_rig.errors import ConfigError, RigError
from accelcal_rig.fit.calibration import CalibrationFile, GyroCalibration, SensorCalibration, load_calibration
from accelcal_rig.fit.sfem import PARAMETER_NAMES
from accelcal_rig.report import certificate_decision, certificate_gyro, certificate_lab
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.read import dut_description, usable_campaign
from accelcal_rig.store.records import utc_now

#: On every page of a dry run's certificate.
DRY_RUN_PAGES = """
@page { @top-center { content: "SIMULATED — no physical sensor was calibrated"; font-family: "DejaVu Sans",
                      sans-serif; font-size: 9pt; font-weight: bold; color: #a00000; } }
"""

STYLE = """
@page { size: A4; margin: 16mm 15mm 18mm 15mm;
        @bottom-center { content: "Certificate " string(number) " — page " counter(page) " of " counter(pages);
                         font-family: "DejaVu Sans", sans-serif; font-size: 8pt; color: #555; } }
section { break-inside: avoid; }
body { font-family: "DejaVu Sans", sans-serif; font-size: 9pt; color: #111; max-width: 190mm; margin: auto; }
h1 { font-size: 15pt; margin: 0 0 2mm 0; } h2 { font-size: 10.5pt; margin: 4mm 0 1mm 0; border-bottom: 0.6pt solid #888; }
.number { string-set: number content(); }
table { border-collapse: collapse; width: 100%; margin: 1mm 0; }
th, td { border: 0.4pt solid #bbb; padding: 1pt 4pt; text-align: right; vertical-align: top; }
th { background: #eee; } td.text, th.text { text-align: left; } td.key { text-align: left; width: 34%; color: #333; }
.verdict { font-size: 14pt; font-weight: bold; padding: 2mm 4mm; display: inline-block; border: 1.2pt solid; }
.banner { border: 1.2pt solid #a00000; color: #a00000; font-weight: bold; padding: 1.5mm 3mm; margin: 2mm 0; }
.note { color: #444; font-size: 8pt; }
.signatures td { height: 10mm; vertical-align: bottom; text-align: left; }
"""


@dataclass(frozen=True)
class Written:
    serial: str
    html: Path
    pdf: Path | None


def write_certificates(campaign_path: Path, calibration_path: Path, folder: Path, operator: str = "",
                       pdf: bool = True) -> tuple[list[Written], list[str]]:
    """One draft certificate per DUT of the calibration into `folder` (created): every page says it is not
    issued until a person approves it (rig approve issues it as a revision); (what was written, warnings).
    Refused in one line when the calibration was fitted to other measurements than the campaign's. Each DUT's
    PDF is written before its HTML page: a page that names the calibration's certificate number marks a
    certificate written whole (certificate_current)."""
    campaign, calibration = _certifiable(campaign_path, calibration_path)
    folder.mkdir(parents=True, exist_ok=True)
    render = _pdf_renderer() if pdf else None
    warnings = [] if render is not None or not pdf else [
        "PDFs need WeasyPrint: pip install 'accelcal-rig[certificate]' (HTML certificates written)"]
    written: list[Written] = []
    for serial, name in certificate_names(list(calibration.sensors)).items():
        sensor = calibration.sensors[serial]
        page = certificate_html(campaign, campaign_path, calibration, calibration_path, serial, sensor, operator)
        pdf_path = None
        clear_dead_temporaries(folder / f"{name}.pdf", folder / f"{name}.html")  # what a killed writer left
        if render is not None:
            pdf_path = folder / f"{name}.pdf"
            write_atomically(pdf_path, _rendered_pdf(render, page, pdf_path), "the certificate")
        html_path = folder / f"{name}.html"
        write_text_atomically(html_path, page, "the certificate")
        written.append(Written(serial, html_path, pdf_path))
    return written, warnings


def certificate_names(serials: Sequence[str]) -> dict[str, str]:
    """Each serial's certificate file name (without suffix): the serial with what a file name cannot hold
    replaced, numbered where two serials would otherwise share one."""
    names: dict[str, str] = {}
    for serial in serials:
        name = re.sub(r"[^A-Za-z0-9_.-]", "_", serial)
        if name in names.values():
            name += f"-{len(names) + 1}"
        names[serial] = name
    return names


def certificate_current(page: Path, pdf: Path | None, calibration: CalibrationFile, serial: str) -> bool:
    """Whether the draft certificate in `page` (and `pdf`, when one is due) was written from `calibration`:
    the page names its certificate number, and the PDF, written just before it, is there."""
    try:
        text = page.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    number = certificate_number_of(serial, calibration)
    return number in text and (pdf is None or pdf.is_file())


def certificate_number_of(serial: str, calibration: CalibrationFile) -> str:
    """The draft certificate number of a DUT of a calibration (revision 1's base)."""
    return certificate_lab.certificate_number(serial, calibration).base


@dataclass(frozen=True)
class Approval:
    """Who approved the certificate revision being issued, and when (UTC date); a reissue's reason."""

    approver: str
    date: str
    reason: str = ""


@dataclass(frozen=True)
class Rendered:
    number: str
    html: str
    pdf: bytes | None


def render_certificate(campaign_path: Path, calibration_path: Path, serial: str, revision: int, approver: str,
                       pdf: bool = True, reason: str = "", operator: str = "") -> Rendered:
    """One DUT's certificate issued as `revision`, approved by `approver` today: what an approval keeps."""
    campaign, calibration = _certifiable(campaign_path, calibration_path)
    sensor = calibration.sensors.get(serial)
    if sensor is None:
        raise ConfigError(f"{calibration_path}: no sensor {serial}")
    approval = Approval(approver, utc_now()[:10], reason)
    page = certificate_html(campaign, campaign_path, calibration, calibration_path, serial, sensor, operator, revision,
                            approval)
    render = _pdf_renderer() if pdf else None
    number = certificate_number(campaign, sensor, calibration, revision).base
    return Rendered(number, page, None if render is None else _rendered_pdf(render, page, calibration_path))


def _certifiable(campaign_path: Path, calibration_path: Path) -> tuple[Campaign, CalibrationFile]:
    """The campaign and its calibration, refused in one line when the calibration was fitted to other
    measurements than the campaign holds, or before budgets and verdicts were stated."""
    campaign = usable_campaign(campaign_path)
    calibration = load_calibration(calibration_path)
    if calibration.source.get("measurements_sha256") != measurements_sha256(campaign):
        raise ConfigError(f"{calibration_path}: fitted to other measurements than {campaign_path} holds now: fit it "
                          "again (rig fit) before certifying")
    judged: list[tuple[str, SensorCalibration | GyroCalibration]] = [*calibration.sensors.items(),
                                                                     *calibration.gyroscopes.items()]
    old = [s for s, c in judged if "uncertainty_budget" not in c.metrics or c.verdict is None]
    if old:
        raise ConfigError(f"{calibration_path}: sensor {old[0]} has no uncertainty budget or verdict (written by an "
                          "earlier accelcal-rig): fit it again (rig fit) before certifying")
    return campaign, calibration


def _rendered_pdf(render: Any, page: str, where: Path) -> bytes:
    try:
        return bytes(render(page))
    except Exception as exc:  # noqa: BLE001 - a renderer's failure is one line naming the file
        raise RigError(f"{where}: the PDF could not be rendered: {str(exc).splitlines()[0]}") from None


def pdf_renderer_available() -> bool:
    """Whether PDFs can be written here (WeasyPrint and its system libraries)."""
    return _pdf_renderer() is not None


def _pdf_renderer() -> Any:
    try:
        from weasyprint import HTML
    except (ImportError, OSError):  # not installed, or its system libraries (Pango) are missing
        return None
    return lambda page: HTML(string=page).write_pdf()


def _e(value: object) -> str:
    return html.escape(str(value))


def _rows(rows: list[tuple[str, object]]) -> str:
    return "<table>" + "".join(f"<tr><td class='key'>{_e(k)}</td><td class='text'>{_e(v)}</td></tr>"
                               for k, v in rows) + "</table>"


def _grid(header: list[str], rows: Sequence[Sequence[object]], text_columns: int = 1) -> str:
    def cell(tag: str, i: int, value: object) -> str:
        return f"<{tag}{' class=text' if i < text_columns else ''}>{_e(value)}</{tag}>"

    head = "".join(cell("th", i, h) for i, h in enumerate(header))
    body = "".join("<tr>" + "".join(cell("td", i, v) for i, v in enumerate(row)) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def certificate_number(campaign: Campaign, sensor: SensorCalibration, calibration: CalibrationFile,
                       revision: int = 1) -> certificate_lab.CertificateNumber:
    """Unique to the DUT, its measurements and their fit, with its revision (certificate_lab)."""
    return certificate_lab.certificate_number(sensor.serial, calibration, revision)


def certificate_html(campaign: Campaign, campaign_path: Path, calibration: CalibrationFile, calibration_path: Path,
                     serial: str, sensor: SensorCalibration, operator: str = "", revision: int = 1,
                     approval: Approval | None = None) -> str:
    """The certificate's page; without `approval` a draft, every page saying it is not issued yet."""
    dut = dut_description(campaign, serial)
    attrs, metrics = campaign.attrs, sensor.metrics
    number = certificate_number(campaign, sensor, calibration, revision)
    banners = [] if approval is not None else [
        "DRAFT: not issued until a person approves it (rig approve, or the dashboard)."]
    if attrs.get("dry_run"):
        banners.append("SIMULATED: a dry run against simulated instruments. No physical sensor was calibrated.")
    if calibration.source.get("partial"):
        banners.append(f"PARTIAL: {calibration.source['partial']}.")
    uncalibrated = calibration.duts[serial].not_calibrated if serial in calibration.duts else {}
    gyro = calibration.gyroscopes.get(serial)
    covered = "accel and gyro channels" if gyro is not None else "accel channel"
    banners += [f"NOT CALIBRATED: its {channel} channel ({why}). This certificate covers its {covered} only."
                for channel, why in uncalibrated.items()]
    style = STYLE + certificate_decision.STYLE + (DRY_RUN_PAGES if attrs.get("dry_run") else "") + (GYRO_STYLE if gyro is not None else "")
    item = ("MEMS IMU: accelerometer and gyroscope" if gyro is not None
            else f"MEMS accelerometer{' channel' if uncalibrated else ''}")
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>Calibration certificate {_e(number)}"
             f"</title><style>{style}</style><style>{certificate_lab.LAB_STYLE}</style></head><body>",
             certificate_lab.header_html(campaign),
             f"<h1>Calibration certificate: {item}</h1>",
             f"<p>Certificate <b class='number'>{_e(number)}</b> — "
             f"{'issued ' + _e(approval.date) if approval else 'draft of ' + _e(utc_now()[:10])} by accelcal-rig "
             f"{_e(__version__)}</p>",
             *(f"<div class='banner'>{_e(b)}</div>" for b in banners)]
    parts += ["<div class='front'>", "<h2>Item calibrated</h2>", _rows([
        ("serial", serial),
        ("part", f"{dut.get('part', '?')}: {_identity(campaign, serial)}"),
        ("configured", f"±{dut.get('range_g', '?')} g, {dut.get('odr_hz', '?')} Hz, {float(dut.get('lsb_g', 0)) * 1e6:.4g} µg "
                       "per code"),
        ("mount on the fixture", f"{dut.get('name', '')} ({', '.join(f'{a:g}' for a in dut.get('mount_euler_deg', []))}° "
                                 "xyz Euler)"),
        *certificate_lab.item_rows(campaign, serial),
    ])]
    parts += ["<h2>Calibration</h2>", _rows([
        *certificate_lab.calibration_rows(campaign, campaign_path.name, calibration, calibration_path.name, sensor,
                                          gyro is not None),
        ("gravity", gravity_statement(float(metrics.get("gravity_m_s2", 9.80665)))),
        *certificate_lab.environment_rows(campaign, serial),
        ("performed by", operator or "—"),
    ]), certificate_lab.traceability_html(campaign), "</div>"]
    accel = " (accelerometer)" if gyro is not None else ""
    parts += ["<section>", f"<h2>Results{accel}</h2>", _results(sensor), "</section>"]
    parts += ["<section>", f"<h2>Verification{accel} (poses the calibration never saw)</h2>", _verification(metrics),
              "</section>"]
    parts += ["<section>", f"<h2>Uncertainty of a compensated reading{accel}</h2>", _uncertainty(metrics), "</section>"]
    if gyro is not None:
        parts += _gyro_sections(gyro)
    noise = certificate_gyro.noise(sensor, gyro)
    if noise:
        parts += ["<section>", "<h2>Noise (Allan deviation)</h2>", noise, "</section>"]
    parts += certificate_decision.conformity_section(sensor, gyro)
    parts += ["<section><h2>Signatures</h2>",
              "<table class='signatures'><tr><th class='text'></th><th class='text'>name</th><th class='text'>date"
              "</th><th class='text'>signature</th></tr>"
              f"<tr><td>performed by</td><td>{_e(operator)}</td><td></td><td></td></tr>"
              f"<tr><td>approved by</td><td>{_e(approval.approver if approval else '')}</td>"
              f"<td>{_e(approval.date if approval else '')}</td><td></td></tr></table>",
              *([f"<p>Revision {revision} replaces revision {revision - 1}: {_e(approval.reason)}</p>"]
                if approval is not None and revision > 1 and approval.reason else []),
              "<p class='note'>The results refer only to the item calibrated, under the conditions stated, within "
              f"the calibrated temperature range {sensor.validity_c[0]:.2f} … {sensor.validity_c[1]:.2f} °C. Outside "
              f"it the calibration {'is clamped to its edge' if sensor.out_of_range == 'clamp' else 'extrapolates'}."
              "</p>", certificate_lab.end_html(number), "</section></body></html>"]
    return "\n".join(parts)


#: An IMU's certificate states two sensors on at most two pages: its tables a little tighter.
GYRO_STYLE = """
body { font-size: 7.5pt; } h1 { font-size: 13pt; } h2 { font-size: 9.5pt; margin: 2.5mm 0 0.8mm 0; }
th, td { padding: 0.3pt 3pt; } p { margin: 0.8mm 0; } ul { margin: 0.5mm 0; } .signatures td { height: 10mm; }
"""


def _gyro_sections(gyro: GyroCalibration) -> list[str]:
    """The gyroscope's results, verification, uncertainty and the statements of how it was referenced."""
    return ["<section>", "<h2>Results (gyroscope)</h2>", certificate_gyro.gyro_results(gyro),
            certificate_gyro.gyro_statements(gyro), "</section>",
            "<section>", "<h2>Verification (gyroscope: rate steps the calibration never saw)</h2>",
            certificate_gyro.gyro_verification(gyro), "</section>",
            "<section>", "<h2>Uncertainty of a compensated rate (gyroscope)</h2>", certificate_gyro.gyro_uncertainty(gyro),
            "</section>"]


def _identity(campaign: Campaign, serial: str) -> str:
    """The identity registers as the last run's preflight read them (its event log)."""
    prefix = f"sensor {serial}: "
    found = [e.message[len(prefix):] for e in campaign.events if e.kind == "preflight" and e.message.startswith(prefix)]
    return found[-1] if found else "identity not recorded"


#: (label, parameter index, factor to the unit shown, offset, format) of each row of the results table.
_RESULT_ROWS = [
    *((f"bias {axis} (mg)", k, 1e3, 0.0, "+.3f") for k, axis in enumerate("xyz")),
    *((f"scale error {axis} (ppm)", 3 + k, 1e6, -1.0, "+.0f") for k, axis in enumerate("xyz")),
    *((f"non-orthogonality {name} (mrad)", 6 + k, 1e3, 0.0, "+.4f") for k, name in enumerate(("yx", "zx", "zy"))),
]
_MISALIGNMENT_ROWS = [(f"misalignment {axis} (mrad)", 9 + k, 1e3, 0.0, "+.4f") for k, axis in enumerate("xyz")]


def _results(sensor: SensorCalibration) -> str:
    low, high = sensor.validity_c
    temperatures = np.array([low, 0.5 * (low + high), high])
    values = sensor.parameters_at(temperatures)              # (3, 12)

    def cell(i: int, k: int, factor: float, offset: float, spec: str) -> str:
        u = certificate_decision.expanded_at(sensor.metrics, PARAMETER_NAMES[k], float(temperatures[i]))
        text = format((values[i, k] + offset) * factor, spec)
        return text if u is None else f"{text} ± {format(u * factor, spec.lstrip('+'))}"

    rows = [[label, *(cell(i, k, factor, offset, spec) for i in range(3))]
            for label, k, factor, offset, spec in _RESULT_ROWS + (_MISALIGNMENT_ROWS if sensor.mode == "reference" else [])]
    return (f"<p>Calibrated range {low:.2f} … {high:.2f} °C (the DUT's own temperature sensor). Parameters of Eq. 1, "
            "U<sub>SF</sub> = M·C·S·(U − b), at the ends and the middle of the range, each ± its expanded uncertainty "
            "(k = 2: the fit's, carried through its polynomial, the thermal model's scatter and, for the scale "
            "factors, the site's gravity); the full polynomials are in the calibration file.</p>"
            + _grid(["parameter", *(f"at {t:.2f} °C" for t in temperatures)], rows))


def _verification(metrics: dict[str, Any]) -> str:
    v = metrics.get("verification")
    if v is None:
        return "<p><b>No verification poses:</b> the calibration was not checked on poses it was not fitted to.</p>"
    temperatures = ", ".join(f"{r['setpoint_c']:g}" for r in v["by_setpoint"])
    expanded = v.get("expanded_u", {})

    def u(key: str, spec: str = ".4f") -> str:
        return f" ± {format(expanded[key], spec)}" if key in expanded else ""

    drift_u = expanded.get("drift_mg")
    drift = ", ".join(f"{d * 1e3:.1f}" + (f" ± {drift_u[a] * 1e3:.1f}" if drift_u else "") for a, d in enumerate(v["drift_mg"]))
    return _rows([
        ("poses", f"{v['n_poses']} at {temperatures} °C"),
        ("|g| RMSE (Eq. 9)", f"{v['rmse_mg']:.4f}{u('rmse_mg')} mg (their noise floor {v['noise_floor_mg']:.4f} mg)"),
        ("largest axis error", f"{v['max_axis_error_mg']:.4f}{u('max_axis_error_mg')} mg ({v['frame']})"),
        ("largest tilt error (Eq. 10)", f"{v['max_tilt_error_deg']:.4f}{u('max_tilt_error_deg')}°"),
        ("residual zero-g drift x, y, z", drift + " µg over the range"),
    ]) + ("<p class='note'>± the figure's expanded uncertainty (k = 2) as a measurement of the calibrated DUT's "
          "error: the table's pointing, the site's gravity and the reading's noise.</p>" if expanded else "")


def _uncertainty(metrics: dict[str, Any]) -> str:
    budget = metrics["uncertainty_budget"]
    rows = [[name.replace("_", " "), *(f"{u * 1e3:.1f}" for u in values)] for name, values in budget["sources_mg"].items()]
    rows.append(["combined standard uncertainty", *(f"{u * 1e3:.1f}" for u in budget["standard_mg"])])
    rows.append([f"expanded uncertainty (k = {budget['coverage_factor']:g}, about 95 %)",
                 *(f"{u * 1e3:.1f}" for u in budget["expanded_mg"])])
    coverage = metrics.get("truth_coverage_k2")
    check = (f"<p class='note'>Checked against the simulation truth: {coverage * 100:.1f} % of the verification "
             "poses' axis errors lie inside their expanded uncertainty.</p>" if coverage is not None else "")
    return ("<p>For " + _e(budget["reading"]) + ": each source's largest standard uncertainty over every orientation "
            "and the calibrated range, per axis (GUM, sources uncorrelated).</p>"
            + _grid(["source", "x (µg)", "y (µg)", "z (µg)"], rows) + check)
