"""A certificate's statement of conformity (ISO/IEC 17025:2017 §7.8.6): the decision rule, and for each limit
the figure that decided it — its value with its sign, its expanded uncertainty, the limit and the outcome;
or, without limits, that no conformity is stated. Also each parameter's expanded uncertainty as the fit
stated it, for the results tables."""

from __future__ import annotations

import html

from accelcal_rig.fit.acceptance import combined_verdict
from accelcal_rig.fit.calibration import ChannelCalibration
from accelcal_rig.fit.decision import LimitCheck, worst

STYLE = """
.PASS { color: #0a5a0a; } .FAIL { color: #a00000; } .CONDITIONAL { color: #8a5a00; }
td.outcome { text-align: left; font-weight: bold; }
"""


def _e(value: object) -> str:
    return html.escape(str(value))


def _checks(calibration: ChannelCalibration) -> list[LimitCheck]:
    """Of each limit, the figure that decided it (the worst outcome, then the least margin)."""
    checks = [LimitCheck(**c) for c in calibration.decision.get("limits", [])]
    keys = dict.fromkeys(c.limit_key for c in checks)
    return [worst([c for c in checks if c.limit_key == key]) for key in keys]


def _table(checks: list[LimitCheck]) -> str:
    def value(c: LimitCheck) -> str:
        return f"{c.value:+.4g}" if c.signed else f"{c.value:.4g}"

    rows = "".join(
        f"<tr><td class='text'>{_e(c.label)}</td><td>{_e(value(c))}</td>"
        f"<td>{_e('—' if c.expanded_u is None else f'{c.expanded_u:.2g}')}</td>"
        f"<td>{_e(('±' if c.signed else '≤ ') + f'{c.limit:g}')}</td><td class='text'>{_e(c.unit)}</td>"
        f"<td class='outcome'>{_e(c.outcome)}</td></tr>" for c in checks)
    return ("<table><tr><th class='text'>figure judged (of each limit, the one that decided it)</th><th>value</th>"
            "<th>U (k = 2)</th><th>limit</th><th class='text'>unit</th><th class='text'>outcome</th></tr>"
            f"{rows}</table>")


def conformity_section(labelled: list[tuple[str, ChannelCalibration]]) -> list[str]:
    """The statement of conformity: none without limits; else the rule, the DUT's verdict and each channel's
    deciding figures (each under its sensor's name, where the DUT has several)."""
    sensors = [calibration for _, calibration in labelled]
    if all(c.verdict in (None, "NOT JUDGED") for c in sensors):
        return ["<section><h2>Statement of conformity</h2><p>None: the procedure states no acceptance limits (no "
                "specification to judge against). The results above are stated with their uncertainties.</p></section>"]
    verdict = combined_verdict([c.verdict for c in sensors])
    rule = next((c.decision.get("decision_rule") for c in sensors if c.decision.get("decision_rule")), "")
    parts = ["<section><h2>Statement of conformity against the procedure's acceptance limits</h2>",
             f"<p><span class='verdict {_e(verdict)}'>{_e(verdict)}</span></p>",
             f"<p><b>Decision rule:</b> {_e(rule or 'not recorded (a calibration fitted before rules were stated)')}."
             "</p>"]
    if verdict == "CONDITIONAL":
        beyond = [c for s in sensors for c in _checks(s) if c.outcome == "conditional fail"]
        parts.append("<p>A figure lies within its guard band: the measurement's uncertainty does not allow a pass or "
                     "a fail to be stated with the confidence the rule asks. "
                     + (f"<b>Conditional fail:</b> {_e('; '.join(c.label for c in beyond))} measured beyond the limit."
                        if beyond else "Each such figure was measured within its limit (conditional pass).")
                     + "</p>")
    for label, calibration in (labelled if len(labelled) > 1 else [("", c) for _, c in labelled]):
        head = (f"<p>{_e(label)}: <b class='{_e(calibration.verdict or '')}'>{_e(calibration.verdict or 'NOT JUDGED')}"
                "</b></p>") if label else ""
        checks = _checks(calibration)
        if checks:
            parts.append(head + _table(checks))
        else:
            reasons = "".join(f"<li>{_e(r)}</li>" for r in calibration.verdict_reasons)
            parts.append(f"{head}<ul>{reasons}</ul>")
    notes = [r for c in sensors for r in c.verdict_reasons if not any(r == k.text() for k in _checks(c))
             and c.decision.get("limits")]
    if notes:
        parts.append("<ul>" + "".join(f"<li>{_e(r)}</li>" for r in notes) + "</ul>")
    parts.append("<p class='note'>Each figure's expanded uncertainty is its own: a verification figure's from the "
                 "references it was measured against and the reading's noise, a parameter's from the fit carried "
                 "through its polynomial to the judged temperature. Every figure judged is in the calibration file."
                 "</p></section>")
    return parts
