"""`rig approve` and `rig registry user | audit | certificate`: a person's decision on each DUT's calibration,
recorded append-only with who, how and when; the certificate revision an approval issues, kept in the
registry and written beside the campaign."""

from __future__ import annotations

import argparse
import getpass
import json
import sys
from typing import Any

from accelcal_rig.errors import ConfigError


def approve_command(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.follow_up import campaign_registry_url
    from accelcal_rig.cli.registry_access import campaign_entries
    from accelcal_rig.registry.approvals import Approvals
    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.location import described
    from accelcal_rig.report.certificate import certificates_folder, write_issued
    from accelcal_rig.web.issuing import issued_certificate

    campaign = args.campaign
    calibration = args.calibration or campaign.with_suffix(".calibration.yaml")
    amendments = {"customer": args.customer, "contact": args.contact, "received_date": args.received,
                  "condition": args.condition, "remarks": args.remarks}
    if args.action != "reissue" and any(value is not None for value in amendments.values()):
        raise ConfigError("--customer, --contact, --received, --condition, --remarks: only a reissue amends a "
                          "certificate (rig approve --reissue --reason …)")
    if not campaign.is_file():
        raise ConfigError(f"{campaign}: no such campaign file")
    url = campaign_registry_url(campaign, args.registry)  # where its run recorded it (a dry run's: the dry runs')
    registry = Registry.open(url, upgrade=True, create=False)
    approvals = Approvals(registry)
    user = _authenticated(approvals, args.user, args.password_stdin)
    authority = f"rig approve, password of registry user {user.name} (operating-system user {_os_user()})"
    entries = campaign_entries(campaign, calibration)
    simulated = any(entry["simulated"] for entry in entries)
    serials = list(dict.fromkeys(e["serial"] for e in entries))
    unknown = [s for s in (args.serial or []) if s not in serials]
    if unknown:
        raise ConfigError(f"{campaign}: no DUT {unknown[0]} in its calibration (DUTs: {', '.join(serials)})")
    ids = registry.ids_of(entries)
    for serial in args.serial or serials:
        if serial not in ids:
            raise ConfigError(f"{campaign}: DUT {serial}'s calibration is not in registry {described(url)}, where its "
                              f"run records it: rig resume {campaign} records it there")
        lead = ids[serial]
        decision = approvals.decision(lead)
        if args.action == "approve" and decision.state == "approved":
            # A kill after the registry recorded it, before the files were written: they come from the registry.
            kept = approvals.certificate(lead, decision.revision) if decision.revision else None
            restored = write_issued(certificates_folder(campaign), serial, int(kept["revision"]), kept["html"],
                                    None if kept["pdf"] is None else bytes(kept["pdf"]), only_missing=True) if kept else []
            print(f"{serial}: approved already (revision {decision.revision}, by {decision.by}); a new revision needs "
                  "--reissue --reason" + (f"; its certificate written again → {', '.join(map(str, restored))}"
                                          if restored else ""))
            continue
        issued, at = None, None
        if args.action != "reject":
            issued, at = issued_certificate(approvals, lead, serial, args.action, user, authority, args.reason,
                                            campaign, calibration, amendments, pdf=not args.no_pdf,
                                            operator=args.operator)
        revision_issued = approvals.record(lead, args.action, user, authority, args.reason, issued, at)
        if issued is not None:
            written = write_issued(certificates_folder(campaign), serial, issued.revision, issued.html, issued.pdf)
            print(f"{serial}: {args.action}d by {user.full_name}; certificate {issued.number} revision "
                  f"{revision_issued} → {', '.join(str(p) for p in written)}"
                  + (" (SIMULATED: a dry run's, in the dry runs' registry)" if simulated else ""))
        else:
            print(f"{serial}: rejected by {user.full_name}: {args.reason}")
    return 0


def _authenticated(approvals: Any, name: str, from_stdin: bool) -> Any:
    """The approver, by their password (asked for, or one line on standard input)."""
    user = approvals.user(name)
    if user is None:
        raise ConfigError(f"registry {approvals.registry.url}: no user {name} (rig registry user add)")
    if not user.may_approve:
        raise ConfigError(f"user {name} may not approve (role {user.role}{', disabled' if user.disabled else ''})")
    from accelcal_rig.registry.approvals import COMMAND_LINE, utc_now_naive
    from accelcal_rig.registry.sign_ins import SignIns

    sign_ins = SignIns(approvals.registry)
    locked_s = sign_ins.locked_for_s(name, utc_now_naive())
    if locked_s > 0:
        raise ConfigError(f"user {name}: locked out after too many failed logins, for {locked_s / 60:.0f} more min "
                          f"(rig registry user enable {name} unlocks it)")
    password = _password(from_stdin, f"password of {name}: ")
    found = approvals.authenticate(name, password)
    if found is None:
        sign_ins.failed(name, COMMAND_LINE, utc_now_naive())
        raise ConfigError(f"user {name}: wrong password (or no password here: a reverse proxy's user approves "
                          "on the dashboard)")
    sign_ins.signed_in(name, COMMAND_LINE, utc_now_naive())
    return found


def _password(from_stdin: bool, prompt: str) -> str:
    if from_stdin:
        return sys.stdin.readline().rstrip("\n")
    if not sys.stdin.isatty():
        raise ConfigError("a password is needed: run in a terminal, or give it with --password-stdin")
    return getpass.getpass(prompt)


def _os_user() -> str:
    try:
        return getpass.getuser()
    except (KeyError, OSError):
        return "unknown"


def user_command(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.registry_access import open_registry
    from accelcal_rig.registry.approvals import Approvals

    approvals = Approvals(open_registry(args, upgrade=True))
    if args.user_action == "list":
        for user in approvals.users():
            print(f"{user.name:<20} {user.role:<9} {'disabled ' if user.disabled else ''}{user.full_name}")
        return 0
    if not args.name:
        raise ConfigError(f"rig registry user {args.user_action}: name the user")
    _admitted(approvals, args)
    if args.user_action == "add":
        if not args.full_name:
            raise ConfigError("rig registry user add: --full-name is needed (as certificates name the person)")
        password = None if args.no_password else _new_password(args.password_stdin, args.name)
        approvals.add_user(args.name, args.full_name, args.role or "viewer", password, args.function or "")
        print(f"user {args.name} ({args.full_name}) added as {args.role or 'viewer'}"
              + (", no password here: the reverse proxy authenticates them" if password is None else ""))
    elif args.user_action == "password":
        approvals.set_password(args.name, _new_password(args.password_stdin, args.name))
        print(f"user {args.name}: password changed; every session of theirs has ended")
    elif args.user_action == "role":
        if args.role is None:
            raise ConfigError(f"rig registry user role {args.name}: --role approver or viewer")
        approvals.set_role(args.name, args.role)
        print(f"user {args.name}: now {args.role}; every session of theirs has ended")
    elif args.user_action == "function":
        if args.function is None:
            raise ConfigError(f"rig registry user function {args.name}: --function TEXT (e.g. 'Head of laboratory')")
        approvals.set_function(args.name, args.function)
        print(f"user {args.name}: certificates they approve from now on name them as {args.function or '(no function)'}")
    else:
        approvals.set_disabled(args.name, args.user_action == "disable")
        print(f"user {args.name} {args.user_action}d" + ("; every session of theirs has ended"
                                                         if args.user_action == "disable" else
                                                         " (and unlocked, if too many failed logins had locked it)"))
    return 0


def _admitted(approvals: Any, args: argparse.Namespace) -> None:
    """Once the lab has an approver, only an approver changes its users: `--by NAME` with their password (the
    first line on standard input with --password-stdin). The first approver is added freely. (Whoever may
    write the registry's tables directly is beyond this: the database's own privileges decide that.)"""
    if not any(u.may_approve for u in approvals.users()):
        return
    if not args.by:
        raise ConfigError(f"rig registry user {args.user_action}: the lab has approvers: --by APPROVER (with "
                          "their password) is needed to change its users")
    user = _authenticated(approvals, args.by, args.password_stdin)
    if not user.may_approve:
        raise ConfigError(f"user {args.by} may not change users (role {user.role})")


def _new_password(from_stdin: bool, name: str) -> str:
    password = _password(from_stdin, f"new password of {name}: ")
    if not from_stdin and getpass.getpass("again: ") != password:
        raise ConfigError(f"user {name}: the two passwords differ")
    return password


def audit_command(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.registry_access import open_registry
    from accelcal_rig.registry.approvals import Approvals

    if args.sign_ins:
        return _sign_ins(open_registry(args), args.serial, args.json)
    trail = Approvals(open_registry(args)).trail(serial=args.serial)
    if args.json:
        print(json.dumps([{**row, "at": row["at"].isoformat() + "Z"} for row in trail], indent=1))
        return 0
    if not trail:
        print("no decisions recorded" + (f" for {args.serial}" if args.serial else ""))
    for row in trail:
        revision = f" revision {row['revision']}" if row["revision"] is not None else ""
        reason = f": {row['reason']}" if row["reason"] else ""
        print(f"{row['at']:%Y-%m-%d %H:%M:%S}Z  {row['serial']:<16} calibration {row['calibration_id']:>5}  "
              f"{row['action']}{revision} by {row['full_name']} ({row['authority']}){reason}")
    return 0


def _sign_ins(registry: Any, name: str | None, as_json: bool) -> int:
    from accelcal_rig.registry.sign_ins import SignIns

    record = SignIns(registry).record(name)
    if as_json:
        print(json.dumps([{**row, "at": row["at"].isoformat() + "Z"} for row in record], indent=1))
        return 0
    if not record:
        print("no sign-ins recorded" + (f" for {name}" if name else ""))
    for row in record:
        detail = f": {row['detail']}" if row["detail"] else ""
        print(f"{row['at']:%Y-%m-%d %H:%M:%S}Z  {row['user_name']:<20} {row['event']:<15} from {row['client']}{detail}")
    return 0


def certificate_command(args: argparse.Namespace) -> int:
    from accelcal_rig.cli.registry_access import open_registry
    from accelcal_rig.durable import write_atomically
    from accelcal_rig.registry.approvals import Approvals

    approvals = Approvals(open_registry(args))
    if args.revision is None:
        issued = approvals.certificates(args.id)
        if not issued:
            print(f"calibration {args.id}: no certificate issued (it is {approvals.decision(args.id).state})")
        for row in issued:
            print(f"revision {row['revision']}  {row['number']}  issued {row['issued_at']:%Y-%m-%d %H:%M}Z by "
                  f"{row['approver']}  sha256 {row['sha256'][:16]}…" + (f"  ({row['reason']})" if row["reason"] else ""))
        return 0
    row = approvals.certificate(args.id, args.revision)
    if args.output is None:
        sys.stdout.write(row["html"])
        return 0
    if args.output.suffix.lower() == ".pdf":
        if row["pdf"] is None:
            raise ConfigError(f"calibration {args.id} revision {args.revision}: issued as HTML only (no PDF kept)")
        write_atomically(args.output, bytes(row["pdf"]), "the certificate")
    else:
        write_atomically(args.output, row["html"].encode(), "the certificate")
    print(f"certificate {row['number']} revision {args.revision} → {args.output}")
    return 0
