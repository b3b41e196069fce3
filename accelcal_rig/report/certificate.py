"""`rig certificate`: one calibration certificate per DUT, an HTML page and (with WeasyPrint installed, the
`certificate` extra) its PDF, from a campaign file and the calibration fitted to it.

A certificate states only what the two files hold: the item and its identity as read at preflight, the
campaign and its instruments, and for each calibrated channel of the DUT what its channel model states (its
results, verification and uncertainty budget, fit/channel_model.py `sections`) and its noise; the statement
of conformity over every channel; fields for the signatures of who performed and who approved it. A dry run's certificate says on every
page that no physical sensor was calibrated; a partial campaign's says it was partial.
"""

from __future__ import annotations

import html
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from accelcal_rig import __version__
from accelcal_rig.core.extras import install_hint
from accelcal_rig.durable import clear_dead_temporaries, write_atomically, write_text_atomically
from accelcal_rig.errors import ConfigError, RigError
from accelcal_rig.fit.calibration import CalibrationFile, ChannelCalibration, load_calibration
from accelcal_rig.fit.channel_model import Section
from accelcal_rig.fit.channel_models import model_of
from accelcal_rig.report import certificate_decision, certificate_lab
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.follow_up_record import recorded_follow_up
from accelcal_rig.store.read import dut_description, load_campaign, usable_campaign
from accelcal_rig.store.records import utc_now

#: On every page of a dry run's certificate.
DRY_RUN_PAGES = """
@page { @top-center { content: "SIMULATED — no physical sensor was calibrated"; font-family: "DejaVu Sans",
                      sans-serif; font-size: 9pt; font-weight: bold; color: #a00000; } }
"""
#: On every page of a draft: a mark above (beside a dry run's), its own footer, and a watermark across the page
#: (an element fixed in place is drawn on every page of the PDF; on screen, across the window).
DRAFT_PAGES = """
@page { @top-left { content: "DRAFT — NOT ISSUED"; font-family: "DejaVu Sans", sans-serif; font-size: 9pt;
                    font-weight: bold; color: #a00000; }
        @bottom-center { content: "Draft " string(number) " — not a certificate until approved — page "
                         counter(page) " of " counter(pages); font-family: "DejaVu Sans", sans-serif;
                         font-size: 8pt; color: #a00000; } }
.watermark { position: fixed; top: 38%; left: 0; width: 100%; text-align: center; font-size: 96pt;
             font-weight: bold; color: rgba(160, 0, 0, 0.13); transform: rotate(-35deg); z-index: -1; }
"""
#: What a draft's file name ends in (before .html or .pdf); an issued revision's ends in `.rN`.
DRAFT_SUFFIX = ".DRAFT"

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
        f"PDFs need WeasyPrint: {install_hint('pdf')} (HTML certificates written)"]
    written: list[Written] = []
    for serial, name in draft_names(list(calibration.duts)).items():
        page = certificate_html(campaign, campaign_path, calibration, calibration_path, serial, operator)
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


def draft_names(serials: Sequence[str]) -> dict[str, str]:
    """Each serial's draft file name (without .html or .pdf): never the name an issued revision has."""
    return {serial: name + DRAFT_SUFFIX for serial, name in certificate_names(serials).items()}


def issued_name(serial: str, revision: int) -> str:
    """An issued revision's file name (without .html or .pdf)."""
    return f"{certificate_names([serial])[serial]}.r{revision}"


def certificate_current(page: Path, pdf: Path | None, calibration: CalibrationFile, serial: str) -> bool:
    """Whether the draft certificate in `page` (and `pdf`, when one is due) was written from `calibration`:
    the page names its draft's identifier, and the PDF, written just before it, is there."""
    try:
        text = page.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    return draft_identifier(serial, calibration) in text and (pdf is None or pdf.is_file())


def draft_identifier(serial: str, calibration: CalibrationFile) -> str:
    """What a DUT's draft is called in place of a number: not the number its approval will issue (a draft
    cannot be cited as the certificate), yet as unique to the measurements and the fit."""
    return certificate_lab.draft_identifier(serial, calibration)


def write_issued(folder: Path, serial: str, revision: int, page: str, pdf: bytes | None,
                 only_missing: bool = False) -> list[Path]:
    """An issued revision as files in `folder` (where the run's certificates are): SERIAL.rN.pdf (written first)
    and .html; earlier revisions and the draft stay. `only_missing`: write only what is not there (what was
    written, either way)."""
    folder.mkdir(parents=True, exist_ok=True)
    stem = issued_name(serial, revision)
    written = []
    if pdf is not None and not (only_missing and (folder / f"{stem}.pdf").is_file()):
        written.append(folder / f"{stem}.pdf")
        write_atomically(written[-1], pdf, "the certificate")
    if not (only_missing and (folder / f"{stem}.html").is_file()):
        written.append(folder / f"{stem}.html")
        write_text_atomically(written[-1], page, "the certificate")
    return written


@dataclass(frozen=True)
class Approval:
    """Who approved the certificate revision being issued, and when (UTC date); a reissue's reason; the
    electronic approval's record (how the approver was known, the time, which record keeps it); a reissue's
    amendments (what it states in place of the campaign's facts, cumulative), what they changed and which
    revision it replaces."""

    approver: str
    date: str
    reason: str = ""
    function: str = ""
    at: str = ""                                   #: "2026-12-07 14:03 UTC"
    how: str = ""                                  #: the record's authority: "rig approve, password of …"
    record: str = ""                               #: "the laboratory's registry, calibration 17, …"
    amendments: dict[str, str] = field(default_factory=dict)
    changes: tuple[str, ...] = ()
    replaces: str = ""                             #: "revision 1 (issued 2026-12-07)"


@dataclass(frozen=True)
class Rendered:
    number: str
    html: str
    pdf: bytes | None


def render_certificate(campaign_path: Path, calibration_path: Path, serial: str, revision: int, approval: Approval,
                       pdf: bool = True, operator: str = "") -> Rendered:
    """One DUT's certificate issued as `revision` with its `approval`: what an approval keeps. `operator`: who
    performed it, else who its run recorded (a reissue carries it over)."""
    campaign, calibration = _certifiable(campaign_path, calibration_path)
    operator = operator or recorded_operator(campaign)
    if serial not in calibration.duts:
        raise ConfigError(f"{calibration_path}: no sensor {serial}")
    page = certificate_html(campaign, campaign_path, calibration, calibration_path, serial, operator, revision,
                            approval)
    render = _pdf_renderer() if pdf else None
    number = certificate_lab.certificate_number(serial, calibration, revision).base
    return Rendered(number, page, None if render is None else _rendered_pdf(render, page, calibration_path))


def draft_html(campaign_path: Path, calibration_path: Path, serial: str) -> str:
    """One DUT's draft as the campaign and its calibration make it now (what the approver reads before
    deciding): refused in one line as a certificate would be."""
    campaign, calibration = _certifiable(campaign_path, calibration_path)
    if serial not in calibration.duts:
        raise ConfigError(f"{calibration_path}: no sensor {serial}")
    return certificate_html(campaign, campaign_path, calibration, calibration_path, serial,
                            recorded_operator(campaign))


def amend(campaign_path: Path, serial: str, carried: dict[str, str],
          given: dict[str, str | None]) -> tuple[dict[str, str], tuple[str, ...]]:
    """A reissue's amendments: the facts the last revision stated in place of the campaign's (`carried`) with
    those `given` now (None: not amended); (the amendments the new revision states, what changed, in words).
    Refused in one line: a date of receipt that is not a date or is after the calibration, a text of more than
    one line or too long."""
    from accelcal_rig.config.lab import iso_date

    campaign = load_campaign(campaign_path)
    before = {**certificate_lab.item_facts(campaign, serial), **carried}
    amended, changes = dict(carried), []
    first_day = certificate_lab.calibration_dates(campaign)[0]
    for key, value in given.items():
        if value is None:
            continue
        option = "--received" if key == "received_date" else f"--{key}"
        value = value.strip()
        if len(value) > (2000 if key == "remarks" else 200) or any(ord(c) < 32 or ord(c) == 127 for c in value):
            raise ConfigError(f"{option}: not one line of at most {2000 if key == 'remarks' else 200} characters")
        if key == "received_date" and value:
            try:
                value = iso_date(value).isoformat()
            except ValueError as exc:
                raise ConfigError(f"{option}: {exc}") from None
            if value > first_day:
                raise ConfigError(f"{option}: {value} is after the calibration ({first_day}): an item is received "
                                  "before it is calibrated")
        if value != before.get(key, ""):
            amended[key] = value
            changes.append(f"{certificate_lab.AMENDABLE[key]}: {before.get(key) or 'not stated'} → "
                           f"{value or 'not stated'}")
    return amended, tuple(changes)


def recorded_operator(campaign: Campaign) -> str:
    """Who performed the campaign, as its `rig run --operator` recorded it ("" when none was given)."""
    return str(recorded_follow_up(campaign.attrs).get("operator") or "")


def certificates_folder(campaign_path: Path) -> Path:
    """Where the run's certificates are (its `--certificates`, recorded in the campaign), else beside it."""
    recorded = recorded_follow_up(load_campaign(campaign_path).attrs).get("certificates")
    return Path(recorded) if recorded else campaign_path.with_suffix(".certificates")


def _certifiable(campaign_path: Path, calibration_path: Path) -> tuple[Campaign, CalibrationFile]:
    """The campaign and its calibration, refused in one line when the calibration was fitted to other
    measurements than the campaign holds, or before budgets and verdicts were stated."""
    campaign = usable_campaign(campaign_path)
    calibration = load_calibration(calibration_path)
    if calibration.source.get("measurements_sha256") != measurements_sha256(campaign):
        raise ConfigError(f"{calibration_path}: fitted to other measurements than {campaign_path} holds now: fit it "
                          "again (rig fit) before certifying")
    old = [s for s, _, c in calibration.calibrated() if "uncertainty_budget" not in c.metrics or c.verdict is None]
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


def certificate_html(campaign: Campaign, campaign_path: Path, calibration: CalibrationFile, calibration_path: Path,
                     serial: str, operator: str = "", revision: int = 1, approval: Approval | None = None) -> str:
    """The certificate's page; without `approval` a draft, every page saying it is not issued yet."""
    dut = dut_description(campaign, serial)
    attrs = campaign.attrs
    channels = dict(calibration.duts[serial].channels)
    models = {name: model_of(channel) for name, channel in channels.items()}
    draft = approval is None
    number: certificate_lab.CertificateNumber | str = (
        certificate_lab.draft_identifier(serial, calibration) if draft
        else certificate_lab.certificate_number(serial, calibration, revision))
    banners: list[str] = []
    if attrs.get("dry_run"):
        banners.append("SIMULATED: a dry run against simulated instruments. No physical sensor was calibrated.")
    if calibration.source.get("partial"):
        banners.append(f"PARTIAL: {calibration.source['partial']}.")
    uncalibrated = calibration.duts[serial].not_calibrated
    covered = f"{' and '.join(channels)} channel{'s' if len(channels) > 1 else ''}"
    banners += [f"NOT CALIBRATED: its {channel} channel ({why}). This certificate covers its {covered} only."
                for channel, why in uncalibrated.items()]
    several = len(channels) > 1
    style = (STYLE + certificate_decision.STYLE + (DRY_RUN_PAGES if attrs.get("dry_run") else "")
             + (DRAFT_PAGES if draft else "") + (SEVERAL_STYLE if several else ""))
    sensors = [model.sensor for model in models.values()]
    named = ", ".join(sensors[:-1]) + " and " + sensors[-1] if several else sensors[0]
    item = f"MEMS IMU: {named}" if several else f"MEMS {named}{' channel' if uncalibrated else ''}"
    title = f"DRAFT (not issued) {number}" if draft else f"Calibration certificate {number}"
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{_e(title)}"
             f"</title><style>{style}</style><style>{certificate_lab.LAB_STYLE}</style></head><body>",
             *(["<div class='watermark' aria-hidden='true'>DRAFT</div>"] if draft else []),
             certificate_lab.header_html(campaign),
             f"<h1>{'DRAFT of a calibration certificate' if draft else 'Calibration certificate'}: {_e(item)}</h1>",
             (f"<p>Certificate <b class='number'>{_e(number)}</b> — issued {_e(approval.date)} by accelcal-rig "
              f"{_e(__version__)}</p>" if approval is not None else
              f"<div class='banner'>DRAFT: not issued. <b class='number'>{_e(number)}</b> of {_e(utc_now()[:10])} "
              f"(accelcal-rig {_e(__version__)}) has no certificate number: an approval (rig approve, or the "
              "dashboard) issues it, with its number.</div>"),
             *(f"<div class='banner'>{_e(b)}</div>" for b in banners)]
    configured = "; ".join(f"{name} ±{c.range:g} {c.unit}, {_per_code(c.lsb, c.unit)} per code" for name, c in channels.items())
    parts += ["<div class='front'>", "<h2>Item calibrated</h2>", _rows([
        ("serial", serial),
        ("part", f"{dut.get('part', '?')}: {_identity(campaign, serial)}"),
        ("configured", f"{configured}; {dut.get('odr_hz', '?')} Hz"),
        ("mount on the fixture", f"{dut.get('name', '')} ({', '.join(f'{a:g}' for a in dut.get('mount_euler_deg', []))}° "
                                 "xyz Euler)"),
        *certificate_lab.item_rows(campaign, serial, approval.amendments if approval else None),
    ])]
    parts += ["<h2>Calibration</h2>", _rows([
        *certificate_lab.calibration_rows(campaign, campaign_path.name, calibration, calibration_path.name,
                                          [models[n].method(c) for n, c in channels.items()]),
        *(row for n, c in channels.items() for row in models[n].reference_statements(c.metrics)),
        *certificate_lab.environment_rows(campaign, serial),
        ("performed by", operator or "—"),
    ]), certificate_lab.traceability_html(campaign), "</div>"]
    for name, channel in channels.items():
        for section in models[name].sections(channel):
            parts.append(section_html(section, models[name].sensor if several else ""))
    noise = noise_html(channels)
    if noise:
        parts += ["<section>", "<h2>Noise (Allan deviation)</h2>", noise, "</section>"]
    parts += certificate_decision.conformity_section(
        [(models[n].sensor.capitalize(), c) for n, c in channels.items()])
    ranges = "; ".join(f"{name} {c.validity_c[0]:.2f} … {c.validity_c[1]:.2f} °C (outside it "
                       f"{'clamped to its edge' if c.out_of_range == 'clamp' else 'extrapolated'})"
                       for name, c in channels.items())
    remarks = (approval.amendments.get("remarks", "") if approval else "")
    if remarks:
        parts += ["<section><h2>Remarks</h2>", f"<p>{_e(remarks)}</p>", "</section>"]
    parts += ["<section><h2>Signatures</h2>",
              "<table class='signatures'><tr><th class='text'></th><th class='text'>name</th><th class='text'>date"
              "</th><th class='text'>signature</th></tr>"
              f"<tr><td>performed by</td><td>{_e(operator)}</td><td></td><td></td></tr>",
              _approved_row(approval), "</table>",
              *_revision_statement(revision, approval),
              "<p class='note'>The results refer only to the item calibrated, under the conditions stated, within "
              f"the calibrated temperature range: {_e(ranges)}.</p>", certificate_lab.end_html(number),
              "</section></body></html>"]
    return "\n".join(parts)


def _approved_row(approval: Approval | None) -> str:
    """The approver's row: their name and function, the date, and the electronic approval's record in place of
    a handwritten signature (who, how they were known, when, which record keeps it)."""
    if approval is None:
        return "<tr><td>approved by</td><td>not approved: a draft</td><td></td><td></td></tr>"
    who = approval.approver + (f", {approval.function}" if approval.function else "")
    signed = "; ".join(part for part in (
        f"approved electronically at {approval.at}" if approval.at else "",
        approval.how, f"record: {approval.record}" if approval.record else "") if part)
    return (f"<tr><td>approved by</td><td>{_e(who)}</td><td>{_e(approval.date)}</td>"
            f"<td class='electronic'>{_e(signed)}</td></tr>")


def _revision_statement(revision: int, approval: Approval | None) -> list[str]:
    """A reissue names the revision it replaces, why, and what it amended; the rest is carried over."""
    if approval is None or revision == 1:
        return []
    replaced = approval.replaces or f"revision {revision - 1}"
    amended = ("Amended: " + "; ".join(approval.changes) + ". Everything else as " + replaced.split(" (")[0]
               + " stated it." if approval.changes else "Nothing amended: the same statements, reissued.")
    return [f"<p class='revision'>Revision {revision} replaces {_e(replaced)}"
            + (f": {_e(approval.reason)}" if approval.reason else "") + f". {_e(amended)}</p>"]


#: A certificate of several channels states them on at most two pages: its tables a little tighter.
SEVERAL_STYLE = """
body { font-size: 7.5pt; } h1 { font-size: 13pt; } h2 { font-size: 9.5pt; margin: 2.5mm 0 0.8mm 0; }
th, td { padding: 0.3pt 3pt; } p { margin: 0.8mm 0; } ul { margin: 0.5mm 0; } .signatures td { height: 10mm; }
"""


def section_html(section: Section, sensor: str = "") -> str:
    """A model's section as HTML: its title (the sensor's where the certificate has several), paragraphs, facts,
    table and notes, every text escaped."""
    title = f"{sensor.capitalize()}: {section.title}" if sensor else section.title
    parts = ["<section>", f"<h2>{_e(title)}</h2>", *(f"<p>{_e(p)}</p>" for p in section.paragraphs)]
    if section.facts:
        parts.append(_rows(list(section.facts)))
    if section.table is not None:
        parts.append(_grid(list(section.table.header), section.table.rows, section.table.text_columns))
    parts += [f"<p class='note'>{_e(n)}</p>" for n in section.notes]
    return "".join(parts) + "</section>"


def _interval(entry: dict[str, Any], spec: str) -> str:
    return f"{format(entry['value'], spec)} [{format(entry['low'], spec)}, {format(entry['high'], spec)}]"


def noise_html(channels: dict[str, ChannelCalibration]) -> str:
    """Each channel's Allan figures per axis with their 68 % intervals, and the record they come from; "" when
    the campaign had no still record."""
    rows, records = [], []
    for channel in channels.values():
        model = model_of(channel)
        allan, quoted = channel.metrics.get("allan"), model.noise
        if not isinstance(allan, dict) or quoted is None:
            continue
        for key, name, unit, spec in ((quoted.random_walk, quoted.random_walk_label, quoted.random_walk_unit,
                                       quoted.random_walk_spec),
                                      (quoted.instability, "bias instability", quoted.instability_unit,
                                       quoted.instability_spec)):
            if isinstance(allan.get(key), list):
                rows.append([f"{model.sensor}: {name} ({unit})", *(_interval(e, spec) for e in allan[key])])
        if "duration_s" in allan:
            records.append(f"{model.sensor}: {allan['samples']} samples over {allan['duration_s']:.1f} s at "
                           f"{allan['setpoint_c']:g} °C")
    if not rows:
        return ""
    return ("<p>Overlapping Allan deviation of a still record per axis (IEEE Std 952 practice): the random walk and "
            "the bias instability fitted to it, each [68 % interval]. Records: " + _e("; ".join(records)) + ".</p>"
            + _grid(["figure", "x", "y", "z"], rows))


def _identity(campaign: Campaign, serial: str) -> str:
    """The identity registers as the last run's preflight read them (its event log)."""
    prefix = f"sensor {serial}: "
    found = [e.message[len(prefix):] for e in campaign.events if e.kind == "preflight" and e.message.startswith(prefix)]
    return found[-1] if found else "identity not recorded"


def _per_code(lsb: float, unit: str) -> str:
    """A code's size in millionths or thousandths of its unit, as a data sheet states it: 61.04 µg, 61.04 mdps."""
    factor, prefix = (1e6, "µ") if lsb < 1e-3 else (1e3, "m") if lsb < 1.0 else (1.0, "")
    return f"{lsb * factor:.4g} {prefix}{unit}"
