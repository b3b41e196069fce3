"""A campaign's follow-up: what is written after its last pose (the calibration, each DUT's draft
certificate, the registry's rows) tracked like the poses are. Where each part goes is recorded in the
campaign when it starts; whether each part is there and current is read from the parts themselves (a
certificate page naming its calibration's number, a registry row keyed by the campaign and the fit), so a
kill between the last pose and the last registry row leaves nothing a record could contradict.
`rig status` names what is missing or stale; `rig resume` of a complete campaign finishes it, recording
nothing twice."""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from accelcal_rig.errors import ConfigError, RigError

#: The state of a part: written and current, absent, written from other measurements or another fit, or not
#: known (its registry cannot be read now); `not due` before the campaign's poses are all stored.
DONE, MISSING, STALE, UNKNOWN, NOT_DUE = "done", "missing", "stale", "unknown", "not due"


@dataclass(frozen=True)
class FollowUp:
    """Where a campaign's follow-up goes, as `rig run` was told (recorded as absolute paths: a resume may start
    in another folder)."""

    calibration: Path
    certificates: Path
    pdf: bool = True
    operator: str = ""
    #: `--registry` as given (None: the rig config's `registry:`, else the lab's); never one with a password.
    registry: str | None = None
    #: The registry the run recorded in, however it was named (`--registry`, the rig config, an environment
    #: variable, the default file): what a resume records in, from whatever shell, unless told otherwise now;
    #: never one with a password (a resume is then told it again). None: a campaign from before it was kept.
    recorded_registry: str | None = None

    def to_json(self) -> str:
        return json.dumps({**asdict(self), "calibration": str(self.calibration.resolve()),
                           "certificates": str(self.certificates.resolve())})


@dataclass(frozen=True)
class PartState:
    part: str      #: calibration, certificates, registry
    state: str     #: DONE, MISSING, STALE, UNKNOWN or NOT_DUE
    detail: str    #: one line: what is there or what is missing

    def as_dict(self) -> dict[str, str]:
        return asdict(self)


def of_run(args: argparse.Namespace, output: Path, calibration: Path, registry: str | None = None) -> FollowUp:
    """`rig run`'s follow-up: its flags, else beside the campaign; `registry`: the one its rows go to."""
    return FollowUp(calibration, args.certificates or output.with_suffix(".certificates"), not args.no_pdf,
                    args.operator, _recordable(args.registry), _recordable(registry))


def of_campaign(attrs: dict[str, Any], output: Path, args: argparse.Namespace | None = None) -> FollowUp:
    """A stored campaign's follow-up: what its `rig run` recorded, each part overridden by a flag given now
    (`rig resume --certificates …`), else beside the campaign (a campaign from before it was recorded)."""
    from accelcal_rig.store.follow_up_record import recorded_follow_up

    stored = recorded_follow_up(attrs)

    def given(name: str) -> Any:
        return getattr(args, name, None) if args is not None else None

    calibration = given("calibration") or stored.get("calibration") or output.with_suffix(".calibration.yaml")
    certificates = given("certificates") or stored.get("certificates") or output.with_suffix(".certificates")
    pdf = not given("no_pdf") and bool(stored.get("pdf", True))
    return FollowUp(Path(calibration), Path(certificates), pdf, given("operator") or str(stored.get("operator", "")),
                    given("registry") or stored.get("registry"), stored.get("recorded_registry"))


def _recordable(registry: str | None) -> str | None:
    """A `--registry` kept for the resume: not one that holds a password (a resume is told it again, or uses
    the rig config's)."""
    if registry is None:
        return None
    from accelcal_rig.registry.location import described, normalised

    url = normalised(registry)  # a relative path, as this command's folder resolves it
    return url if described(url) == url else None


def registry_of(campaign: Path, follow_up: FollowUp, simulated: bool) -> str:
    """The registry a campaign's calibrations are recorded in (the dry runs' own for a dry run): `--registry`,
    else the one its run recorded in, else as the rig config and the environment say now."""
    from accelcal_rig.registry.location import campaign_rig_registry, recording_url

    return recording_url(follow_up.registry or follow_up.recorded_registry, campaign_rig_registry(campaign), simulated)


def campaign_registry_url(campaign: Path, flag: str | None) -> str:
    """The registry a campaign's calibrations were recorded in: `--registry` (`flag`), else the one its run
    recorded in however it was named, else a dry run's in the dry runs' own and a real one's as the rig config
    and the environment say now. Where `rig approve` looks, as `rig run` printed it."""
    from accelcal_rig.store.read import load_campaign

    attrs = load_campaign(campaign).attrs
    follow_up = of_campaign(attrs, campaign)
    return registry_of(campaign, replace(follow_up, registry=flag or follow_up.registry),
                       bool(attrs.get("dry_run", False)))


def state(campaign_path: Path, follow_up: FollowUp, fit_due: bool = True) -> list[PartState]:
    """Each part of a campaign's follow-up: the calibration, the certificates, the registry rows. Reads only:
    a registry that does not exist is not created."""
    from accelcal_rig.fit.calibration import load_calibration
    from accelcal_rig.store.content import measurements_sha256
    from accelcal_rig.store.read import load_campaign

    campaign = load_campaign(campaign_path)
    if not fit_due:
        return []
    if campaign.state != "done":
        return [PartState("calibration", NOT_DUE, "once the campaign is done")]
    path = follow_up.calibration
    if not path.is_file():
        return [PartState("calibration", MISSING, f"{path}")]
    try:
        calibration = load_calibration(path)
    except ConfigError as exc:
        return [PartState("calibration", STALE, f"{path}: unreadable: {str(exc).splitlines()[0]}")]
    if calibration.source.get("measurements_sha256") != measurements_sha256(campaign):
        return [PartState("calibration", STALE, f"{path}: fitted to other measurements than the campaign's")]
    return [PartState("calibration", DONE, str(path)), _certificates(follow_up, calibration),
            _registry(campaign_path, follow_up, bool(campaign.attrs.get("dry_run", False)))]


def _certificates(follow_up: FollowUp, calibration: Any) -> PartState:
    from accelcal_rig.report.certificate import certificate_current, draft_names

    folder = follow_up.certificates
    names = draft_names(list(calibration.duts))
    pdf = follow_up.pdf and _pdf_available()
    missing = [serial for serial, name in names.items()
               if not certificate_current(folder / f"{name}.html", folder / f"{name}.pdf" if pdf else None,
                                          calibration, serial)]
    if not missing:
        return PartState("certificates", DONE, f"{len(names)} in {folder}")
    written_before = any((folder / f"{names[s]}.html").exists() for s in missing)
    return PartState("certificates", STALE if written_before else MISSING,
                     f"{', '.join(missing)} ({len(missing)} of {len(names)}) in {folder}")


def _pdf_available() -> bool:
    from accelcal_rig.report.certificate import pdf_renderer_available

    return pdf_renderer_available()


def _registry(campaign_path: Path, follow_up: FollowUp, simulated: bool) -> PartState:
    """Whether every calibrated channel of every DUT has its row; UNKNOWN, not an error, when the registry
    cannot be read now."""
    from sqlalchemy.exc import SQLAlchemyError

    from accelcal_rig.registry.database import Registry
    from accelcal_rig.registry.entries import campaign_entries
    from accelcal_rig.registry.location import described

    try:
        url = registry_of(campaign_path, follow_up, simulated)
        entries = campaign_entries(campaign_path, follow_up.calibration)
        if url.startswith("sqlite:///") and not Path(url.removeprefix("sqlite:///")).exists():
            return PartState("registry", MISSING, f"none recorded: {described(url)} is not made yet")
        registry = Registry.open(url, upgrade=False, create=False, read_only=True)
        recorded = registry.ids_of(entries)
    except (RigError, OSError, SQLAlchemyError) as exc:
        return PartState("registry", UNKNOWN, str(exc).splitlines()[0])
    serials = list(dict.fromkeys(str(e["serial"]) for e in entries))
    missing = [s for s in serials if s not in recorded]
    if not missing:
        return PartState("registry", DONE, f"{len(entries)} rows in {described(url)}")
    return PartState("registry", MISSING, f"{', '.join(missing)} ({len(missing)} of {len(serials)} DUTs) not in "
                                          f"{described(url)}")


def incomplete(parts: list[PartState]) -> list[PartState]:
    """The parts a `rig resume` would finish."""
    return [p for p in parts if p.state in (MISSING, STALE, UNKNOWN)]
