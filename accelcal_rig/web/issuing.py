"""Issuing a certificate revision, the same from `rig approve` and from the dashboard: the approval's record
(who, their function, how they were known, when, which record keeps it), a reissue's amendments carried over
from the last revision and amended (ISO/IEC 17025 §7.8.8), what they changed and which revision it replaces,
rendered from the campaign and its calibration. Here because it joins the registry's approvals and the report's
certificate, which know nothing of each other; the command line sits above this package and uses it too."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

from accelcal_rig.errors import ConfigError
from accelcal_rig.registry.approvals import Action, Approvals, IssuedCertificate, User, utc_now_naive
from accelcal_rig.report.certificate import Approval, amend, render_certificate


def issued_certificate(approvals: Approvals, lead: int, serial: str, action: Action, user: User, authority: str,
                       reason: str, campaign: Path, calibration: Path, given: dict[str, str | None],
                       *, pdf: bool = True, operator: str = "",
                       at: datetime | None = None) -> tuple[IssuedCertificate, datetime]:
    """The revision an approval or a reissue issues, and the time it states (to record the decision at).
    Amendments (`given`, None for each not amended) only with a reissue."""
    if action != "reissue" and any(value is not None for value in given.values()):
        raise ConfigError("only a reissue amends a certificate (rig approve --reissue --reason …): the first "
                          "revision states what the campaign recorded")
    at = (at or utc_now_naive()).replace(microsecond=0)
    revision = approvals.next_revision(lead)
    carried = approvals.amendments(lead) if revision > 1 else {}
    amendments, changes = amend(campaign, serial, carried, given)
    replaces = ""
    if revision > 1:
        last = approvals.certificates(lead)[-1]
        replaces = f"revision {last['revision']} (issued {last['issued_at']:%Y-%m-%d})"
    approval = Approval(
        approver=user.full_name, date=f"{at:%Y-%m-%d}", reason=reason, function=user.function,
        at=f"{at:%Y-%m-%d %H:%M:%S} UTC", how=authority,
        record=f"the laboratory's registry, calibration {lead}, certificate revision {revision}",
        amendments=amendments, changes=changes, replaces=replaces)
    rendered = render_certificate(campaign, calibration, serial, revision, approval, pdf=pdf, operator=operator)
    return IssuedCertificate(revision, rendered.number, rendered.html, rendered.pdf, amendments), at
