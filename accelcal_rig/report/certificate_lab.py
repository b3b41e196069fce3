"""What a certificate states of the laboratory and the calibration around its results (ISO/IEC 17025:2017
§7.8.2.1, §7.8.4.1): the laboratory and the place, the customer and the item's receipt, the certificate's
number and revision, the method cited, the environmental conditions the campaign recorded, the instruments by
make, model and serial, and the traceability of each reference, as the campaign file recorded them when it
was created. File paths and instrument endpoints are the lab's business, never the customer's: a file is
named by its base name at most."""

from __future__ import annotations

import hashlib
import html
import re
from dataclasses import dataclass, replace

import numpy as np

from accelcal_rig.config.lab import REFERENCE_LABELS, InstrumentIdentity
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import CalibrationFile
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import dut_description

NOT_STATED = "not stated in the rig config"

#: What the certificate's own sections add to the page style: the laboratory's block and the end mark.
LAB_STYLE = """
.lab { margin: 0 0 2mm 0; } .lab .address { white-space: pre-line; color: #333; }
.end { text-align: center; font-weight: bold; margin: 1.5mm 0 0 0; letter-spacing: 0.5pt; }
.signatures td { height: 9mm; }
table.trace td { text-align: left; } table.trace .nowrap { white-space: nowrap; }
.front { font-size: 0.92em; } .front td, .front th { padding-top: 0.2pt; padding-bottom: 0.2pt; }
.front table.trace { margin-top: 1.5mm; } .front td.key { width: 24%; }
"""

Rows = list[tuple[str, object]]


def _e(value: object) -> str:
    return html.escape(str(value))


@dataclass(frozen=True)
class CertificateNumber:
    """A certificate's unique number and its revision: a reissue of the same calibration keeps the number and
    takes the next revision."""

    base: str
    revision: int = 1

    def __post_init__(self) -> None:
        if self.revision < 1:
            raise ValueError(f"revision {self.revision}: revisions count from 1")

    def revised(self, revision: int | None = None) -> CertificateNumber:
        """The same certificate, reissued as `revision` (default: the next)."""
        return replace(self, revision=self.revision + 1 if revision is None else revision)

    def __str__(self) -> str:
        return f"{self.base} revision {self.revision}"


def certificate_number(serial: str, calibration: CalibrationFile, revision: int = 1) -> CertificateNumber:
    """Unique to the DUT, the measurements and the fit of them: its serial and a digest of the measured data's
    SHA-256 and the calibration file's creation, so a refit is another certificate and writing the same one
    again gives the same number."""
    measured = str(calibration.source.get("measurements_sha256", ""))
    digest = hashlib.sha256(f"{serial}\n{measured}\n{calibration.created}".encode()).hexdigest()
    return CertificateNumber(f"{serial}-{digest[:12].upper()}", revision)


def draft_identifier(serial: str, calibration: CalibrationFile) -> str:
    """A draft's name in place of a number: from the same measurements and fit as the number its approval will
    issue, but another digest, so a draft is never cited by the issued certificate's number."""
    measured = str(calibration.source.get("measurements_sha256", ""))
    digest = hashlib.sha256(f"draft\n{serial}\n{measured}\n{calibration.created}".encode()).hexdigest()
    return f"DRAFT-{digest[:10].upper()}"


def header_html(campaign: Campaign) -> str:
    """The laboratory's name and address, at the top of the first page."""
    attrs = campaign.attrs
    name, address = str(attrs.get("lab_name", "")), str(attrs.get("lab_address", ""))
    if not name:
        return "<div class='lab'><b>Laboratory not stated in the rig config</b> (its <code>lab:</code> section)</div>"
    return f"<div class='lab'><b>{_e(name)}</b><div class='address'>{_e(address)}</div></div>"


def place_of_calibration(campaign: Campaign) -> str:
    place = str(campaign.attrs.get("place_of_calibration", ""))
    if place:
        return place
    return "at the laboratory's address" if campaign.attrs.get("lab_name") else "laboratory not stated in the rig config"


#: What a reissue may amend (ISO/IEC 17025 §7.8.8), by its key, as the certificate names it.
AMENDABLE: dict[str, str] = {"customer": "customer", "contact": "customer's contact", "received_date": "date of receipt",
                             "condition": "condition on receipt", "remarks": "remarks"}


def item_facts(campaign: Campaign, serial: str) -> dict[str, str]:
    """The amendable facts of a DUT as its campaign recorded them ("" for what it does not state)."""
    dut = dut_description(campaign, serial)
    return {key: str(dut.get(key, "")) for key in AMENDABLE}


def item_rows(campaign: Campaign, serial: str, amendments: dict[str, str] | None = None) -> Rows:
    """Whose the item is, their contact, when it was received and in what condition: as a reissue amended them
    (`amendments`), else as the campaign recorded them."""
    dut = {**dut_description(campaign, serial), **(amendments or {})}
    recorded = "customer" in dut   # campaigns from before these were recorded have none of them

    def stated(key: str, what: str) -> str:
        value = str(dut.get(key, ""))
        if value:
            return value
        return f"not stated (the fixture's sensor entry, or {what})" if recorded else "not recorded (an older campaign)"

    return [("customer", stated("customer", "rig run --customer")),
            ("customer's contact", stated("contact", "rig run --contact")),
            ("date of receipt", stated("received_date", "rig run --received")),
            ("condition on receipt", stated("condition", "rig run --condition"))]


def _date(iso: str) -> str:
    return iso[:10] if re.match(r"\d{4}-\d{2}-\d{2}", iso) else "—"


def calibration_dates(campaign: Campaign) -> tuple[str, str]:
    """(first, last) date of the measurements: the campaign's start, and its finish or its last event."""
    last = campaign.finished or (campaign.events[-1].wall_time if campaign.events else "")
    return _date(campaign.header.created), _date(last)


def procedure_text(campaign: Campaign) -> str:
    attrs = campaign.attrs
    version = str(attrs.get("procedure_version", ""))
    return (f"{attrs.get('procedure_name', '')}, version {version}" if version
            else f"{attrs.get('procedure_name', '')} (version not stated in the procedure)")


def method_text(campaign: Campaign, methods: list[str]) -> str:
    """Each channel's fit as its model states it (and the source it follows), and how the campaign took its
    temperatures (where it departs from the paper)."""
    try:
        stated = parse_yaml_text(campaign.header.procedure_yaml, "the stored procedure") or {}
    except ConfigError:
        stated = {}
    ramp = isinstance(stated, dict) and stated.get("method") == "ramp"
    how = ("measured while ramping the temperature (a departure from the paper's soak method)" if ramp
           else "soaked at each temperature, as in the paper")
    return "; ".join([*methods, how])


def calibration_rows(campaign: Campaign, campaign_name: str, calibration: CalibrationFile, calibration_name: str,
                     methods: list[str]) -> Rows:
    """Where, when and how: the place and dates, the procedure and its version, the method cited, the rig's
    instruments, and the files by their base names."""
    first, last = calibration_dates(campaign)
    return [
        ("place of calibration", place_of_calibration(campaign)),
        ("date of calibration", first if first == last else f"{first} … {last}"),
        ("procedure", procedure_text(campaign)),
        ("method", method_text(campaign, methods)),
        ("instruments", f"rig {campaign.attrs.get('rig_name', '')}: "
                        + "; ".join(f"{name} {text}" for name, text in instrument_identities(campaign))),
        ("measured data (SHA-256)", str(calibration.source.get("measurements_sha256", ""))),
        ("files", f"campaign {campaign_name} ({campaign.state}); calibration {calibration_name} (accelcal-rig "
                  f"{calibration.software_version}, {calibration.created})"),
    ]


def instrument_identities(campaign: Campaign) -> list[tuple[str, str]]:
    """The chamber and the turntable by make, model and serial, as the rig config named them."""
    found = []
    for name in ("chamber", "turntable"):
        info = campaign.header.instruments.get(name, {})
        if "make" not in info:
            found.append((name, "not identified (a campaign from before accelcal-rig recorded make, model and serial)"))
            continue
        found.append((name, _identity(info) or f"(make, model and serial {NOT_STATED})"))
    return found


def _identity(info: dict[str, str]) -> str:
    """`make model, serial S` of what the campaign recorded of an instrument ("" when nothing is stated)."""
    return InstrumentIdentity.model_construct(make=str(info.get("make", "")), model=str(info.get("model", "")),
                                              serial=str(info.get("serial", ""))).identity()


#: A dew point an event states (the frost check's preflight line and its waits).
_DEW_POINT = re.compile(r"dew point (-?\d+(?:\.\d+)?) °C")


def _span(values: np.ndarray, unit: str = "°C") -> str:
    finite = values[np.isfinite(values)]
    if not finite.size:
        return "not recorded"
    low, high = f"{float(finite.min()):.1f}", f"{float(finite.max()):.1f}"
    return (f"{low} {unit}" if low == high else f"{low} … {high} {unit}").replace("-", "−")


def environment_rows(campaign: Campaign, serial: str) -> Rows:
    """The conditions the campaign recorded while it measured: the chamber air and the DUT's own temperature
    over every stored pose, the dew point where the frost check read or assumed it; the room is not recorded."""
    n = len(campaign.poses)
    air = np.asarray(campaign.pose_column("chamber_temperature_c"), dtype=float).ravel() if n else np.zeros(0)
    dut = np.asarray(campaign.dut_column(serial, "temperature_c"), dtype=float).ravel() if n else np.zeros(0)
    dew = np.array([float(m) for e in campaign.events if e.kind in ("preflight", "dew-point")
                    for m in _DEW_POINT.findall(e.message)])
    dew_text = (f"dew point {_span(dew)} (as the frost check read or assumed it)" if dew.size
                else "dew point not recorded (the procedure's frost check did not read it)")
    return [
        ("conditions: temperature", f"chamber air {_span(air)} (its controller, before and after each of the {n} "
                                    f"measurements); DUT {_span(dut)} (its own sensor)"),
        ("conditions: humidity, room", f"{dew_text}; the room's temperature and humidity not recorded by the rig"),
    ]


@dataclass(frozen=True)
class ReferenceState:
    """One reference as the campaign recorded it, and whether it was in calibration when the campaign ran."""

    key: str
    info: dict[str, str]              # {} when the rig config did not state it
    overdue: bool

    @property
    def label(self) -> str:
        """What it is the reference for, shortly: "turntable angle"."""
        return REFERENCE_LABELS.get(self.key, self.key.replace("_", " ")).split(" (")[0]


def reference_states(campaign: Campaign) -> list[ReferenceState]:
    """The references the campaign recorded; overdue when due before the last day of the measurements."""
    _, last = calibration_dates(campaign)
    return [ReferenceState(key, info, bool(info.get("due_date")) and last != "—" and info["due_date"] < last)
            for key, info in campaign.header.references.items()]


def traceability_html(campaign: Campaign) -> str:
    """The traceability chain as a table of its own: the statement of what the results are (not) traceable
    through, then each reference with its standard, certificate, issuer and due date; one not stated or overdue
    is named as such."""
    states = reference_states(campaign)
    untraced = "The calibrated temperatures are the DUT's own sensor's readings, not traced."
    if not states:
        statement = ("<b>Not recorded:</b> the campaign file is from before accelcal-rig recorded the rig's references; "
                     "no traceability is stated for these results.")
    elif not any(s.info for s in states):
        statement = (f"<b>Not traceable:</b> no reference is stated in the rig config (its <code>references:</code> "
                     f"for the {_e(', the '.join(s.label for s in states))}). {untraced}")
    else:
        gaps = ([f"the {s.label} (its reference not stated)" for s in states if not s.info]
                + [f"the {s.label} (its reference's calibration was overdue when the measurements were made)"
                   for s in states if s.overdue])
        statement = ("Traceable to the SI through the references below, each within its calibration's due date when "
                     "the measurements were made." if not gaps else "<b>Not traceable</b> through " + _e("; ".join(gaps))
                     + ".") + f" {untraced}"
    head = f"<table class='trace'><tr><td class='key'>traceability</td><td colspan='4'>{statement}</td></tr>"
    if not any(s.info for s in states):
        return head + "</table>"
    rows = ["<tr><th class='text'>reference for</th><th class='text'>standard</th><th class='text'>certificate</th>"
            "<th class='text'>issuer</th><th class='text'>due</th></tr>"]
    for state in states:
        info = state.info
        if not info:
            rows.append(f"<tr><td class='key'>{_e(state.label)}</td><td colspan='4'><b>{NOT_STATED}</b></td></tr>")
            continue
        standard = _identity(info)
        due = _e(info.get("due_date", "")) + (" <b>OVERDUE</b>" if state.overdue else "")
        rows.append(f"<tr><td class='key'>{_e(state.label)}</td><td>{_e(standard or '—')}</td>"
                    f"<td class='nowrap'>{_e(info.get('certificate', ''))}</td><td>{_e(info.get('issuer', ''))}</td>"
                    f"<td class='nowrap'>{due}</td></tr>")
    return head + "".join(rows) + "</table>"


def end_html(number: CertificateNumber | str) -> str:
    """The end mark: of the certificate and its revision, or of a draft (a string: its identifier)."""
    if isinstance(number, str):
        return f"<p class='end'>End of draft {_e(number)}: not issued, not a calibration certificate</p>"
    return f"<p class='end'>End of certificate {_e(number)}</p>"
