"""The grammar of approval: `rig approve` (a person approves, rejects or reissues a DUT's calibration) and the
registry's side of it, `rig registry user | audit | certificate`."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli.grammar.common import Commands, command, number, registry_option


def add_approve_command(commands: Commands) -> None:
    approve = command(commands, "approve", "approve, reject or reissue a campaign's calibrations (a lab's approver)",
                      "A person with the approver role in the registry approves each DUT's calibration: its "
                      "certificate is issued as a new revision naming them, kept in the registry and written "
                      "beside the campaign. A rejection, or a reissue of an approved calibration (a new revision; "
                      "the old one stays retrievable), needs a reason. Every decision is recorded, append-only, "
                      "with who, how and when (rig registry audit). Only approved real calibrations are a "
                      "serial's valid calibration.",
                      "rig approve campaign.h5 --as jdoe --serial ADX355-A001")
    approve.add_argument("campaign", type=Path, help="campaign file (HDF5), fitted and recorded in the registry")
    approve.add_argument("--as", dest="user", required=True, metavar="USER",
                         help="the approver's user name in the registry (rig registry user add)")
    approve.add_argument("--serial", action="append", metavar="SERIAL", help="only this DUT (repeatable; default: all)")
    what = approve.add_mutually_exclusive_group()
    what.add_argument("--reject", dest="action", action="store_const", const="reject", help="reject (needs --reason)")
    what.add_argument("--reissue", dest="action", action="store_const", const="reissue",
                      help="issue a new certificate revision of an approved calibration (needs --reason)")
    approve.set_defaults(action="approve")
    approve.add_argument("--reason", default="", help="why (a rejection's, a reissue's; recorded)")
    amend = approve.add_argument_group("a reissue's amendments (ISO/IEC 17025 §7.8.8): what the new revision states "
                                       "in place of the campaign's (everything else is carried over)")
    amend.add_argument("--customer", help="whose the item is")
    amend.add_argument("--contact", help="the customer's contact")
    amend.add_argument("--received", metavar="YYYY-MM-DD", help="the date of receipt")
    amend.add_argument("--condition", help="the item's condition on receipt")
    amend.add_argument("--remarks", help="remarks the certificate states")
    approve.add_argument("--calibration", type=Path, help="its calibration (default: FILE.calibration.yaml beside it)")
    approve.add_argument("--password-stdin", action="store_true",
                         help="read the approver's password from standard input (else it is asked for)")
    approve.add_argument("--no-pdf", action="store_true", help="issue the HTML certificate only")
    approve.add_argument("--operator", default="", help="who performed the calibration (on the certificate)")
    registry_option(approve)


def add_approval_actions(actions: Commands) -> None:
    """`rig registry user | audit | certificate`."""
    user = command(actions, "user", "the lab's users who approve calibrations: add, list, password, role, function, "
                   "disable, enable",
                   "Users and their roles (approver, viewer) live in the registry; passwords are stored as argon2id "
                   "hashes. A user without a password is one the lab's reverse proxy authenticates (rig serve "
                   "--user-header). A new password, another role or disabling a user ends every session of theirs "
                   "on every dashboard; enable also lifts a lockout after too many failed logins.",
                   "rig registry user add jdoe --full-name 'J. Doe' --role approver")
    registry_option(user)
    user.add_argument("user_action", choices=["add", "list", "password", "role", "function", "disable", "enable"])
    user.add_argument("name", nargs="?", help="the user's name (all but list)")
    user.add_argument("--full-name", help="add: as certificates name the person")
    user.add_argument("--role", choices=["approver", "viewer"], help="add (default viewer), role: what the user may do")
    user.add_argument("--function", help="add, function: what certificates print under the approver's name "
                                         "(e.g. 'Head of laboratory')")
    user.add_argument("--by", metavar="APPROVER", help="the approver making the change (needed once the lab has one; "
                                                      "their password is asked for)")
    user.add_argument("--password-stdin", action="store_true",
                      help="read passwords from standard input, one per line: --by's first, then the new one")
    user.add_argument("--no-password", action="store_true",
                      help="add: no password here (the reverse proxy authenticates this user)")
    audit = command(actions, "audit", "every approval, rejection and reissue, with who, how and when; or every sign-in",
                    "The registry's append-only record of decisions, oldest first; with --sign-ins the record of "
                    "logins, failed logins, lockouts, unlocks, logouts and sessions ended.",
                    "rig registry audit ADX355-A001")
    registry_option(audit)
    audit.add_argument("serial", nargs="?", help="only this DUT (with --sign-ins: only this user)")
    audit.add_argument("--sign-ins", action="store_true", help="the sign-in record instead of the decisions")
    audit.add_argument("--json", action="store_true", help="one JSON list")
    certificate = command(actions, "certificate", "a certificate revision the registry keeps, as issued",
                          "Every revision an approval or a reissue issued stays in the registry: list them, or "
                          "write one out.", "rig registry certificate 12 --revision 1 -o cert.pdf")
    registry_option(certificate)
    certificate.add_argument("id", type=number(1, 2**63 - 1, integer=True), help="a calibration id (rig registry list)")
    certificate.add_argument("--revision", type=number(1, 10_000, integer=True), help="this revision (default: list)")
    certificate.add_argument("-o", "--output", type=Path, help="write it here (.pdf or .html)")
