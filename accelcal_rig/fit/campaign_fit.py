"""Fit every calibrated channel of every DUT of a campaign: one pipeline, whatever the channel measures.

Each DUT's channels are taken in its part's order; each is handed to the channel model of its quantity
(fit/channel_models.py), which reads its records, fits them and states its figures; every channel is judged
against its own limits under the procedure's decision rule, and the DUT's verdict is its channels'. A channel
no model calibrates, or whose records cannot calibrate it, is measured and stored, and the calibration file
says why it has no calibration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial as bind
from pathlib import Path
from typing import Any

from accelcal_rig import __version__
from accelcal_rig.fit.acceptance import NOT_JUDGED, Judgement, combined_verdict, judge, recorded_acceptance
from accelcal_rig.fit.calibration import FORMAT_NAME as CALIBRATION_FORMAT
from accelcal_rig.fit.calibration import FORMAT_VERSION as CALIBRATION_VERSION
from accelcal_rig.fit.calibration import CalibrationFile, ChannelCalibration, DutCalibration, plain, save_calibration
from accelcal_rig.fit.channel_model import ChannelFit, ChannelModel, NotCalibrated
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.early_check import dropped
from accelcal_rig.fit.fixture_pool import map_over_duts
from accelcal_rig.fit.noise_record import noise_allan
from accelcal_rig.fit.options import FitOptions, TemperatureModel
from accelcal_rig.store.content import Campaign, measurements_sha256
from accelcal_rig.store.records import ChannelInfo, utc_now

__all__ = ["FitOptions", "TemperatureModel", "fit_and_save", "fit_campaign", "partial_campaign", "summary_line"]


@dataclass(frozen=True)
class ChannelJob:
    """One channel of one DUT, read and ready for its model's fit (picklable: a large fixture's are fitted in
    worker processes)."""

    serial: str
    info: ChannelInfo
    model: ChannelModel
    records: Any
    allan: dict[str, Any] | None

    @property
    def channel(self) -> str:
        return self.info.name


def fit_job(job: ChannelJob, options: FitOptions) -> ChannelFit | str:
    """The job's channel fitted, or why its records cannot calibrate it."""
    try:
        return job.model.fit(job.records, options, job.allan)
    except NotCalibrated as exc:
        return str(exc)


def channel_jobs(campaign: Campaign, serials: Sequence[str],
                 options: FitOptions) -> tuple[list[ChannelJob], dict[str, dict[str, str]]]:
    """Every calibrable channel of the DUTs, in the DUTs' order and each part's order of channels; and the
    channels that cannot be calibrated, each with why."""
    jobs: list[ChannelJob] = []
    uncalibrated: dict[str, dict[str, str]] = {serial: {} for serial in serials}
    for serial in serials:
        for info in campaign.header.dut_channels(serial):
            stored = _stored(info)
            model = model_for_quantity(info.quantity)
            if model is None:
                uncalibrated[serial][info.name] = stored + f"no channel model calibrates {info.quantity} yet"
                continue
            records = model.records(campaign, info, serial, options)
            if isinstance(records, str):
                uncalibrated[serial][info.name] = stored + records
                continue
            jobs.append(ChannelJob(serial, info, model, records, noise_figures(campaign, serial, info, model)))
    return jobs, uncalibrated


def noise_figures(campaign: Campaign, serial: str, info: ChannelInfo, model: ChannelModel) -> dict[str, Any] | None:
    """The channel's Allan figures where the campaign has noise records and its model quotes them, else None."""
    odr_hz = float(campaign.header.duts[campaign.serials.index(serial)].get("odr_hz") or 0.0)
    if odr_hz <= 0 or model.noise is None:
        return None
    return noise_allan(campaign, serial, info.name, odr_hz, model.noise)


@dataclass(frozen=True)
class FittedChannel:
    """One channel of one DUT fitted and judged, with its noise record's figures (where the campaign has one)."""

    model: ChannelModel
    fit: ChannelFit
    judgement: Judgement
    allan: dict[str, Any] | None

    def calibration(self) -> ChannelCalibration:
        """Its calibration as the file keeps it: verdict, reasons, decision and noise figures with it."""
        allan = {"allan": plain(self.allan)} if self.allan is not None else {}
        return self.fit.calibration.model_copy(update={
            "verdict": self.judgement.verdict, "verdict_reasons": self.judgement.reasons,
            "decision": self.judgement.plain(), "metrics": {**self.fit.calibration.metrics, **allan}})

    def figures(self) -> dict[str, Any]:
        """What `rig fit --json` prints of it."""
        allan = {"allan": plain(self.allan)} if self.allan is not None else {}
        return {"quantity": self.model.quantity, **plain(self.fit.figures), "warnings": self.fit.thermal.warnings,
                "verdict": self.judgement.verdict, "verdict_reasons": self.judgement.reasons,
                "decision": self.judgement.plain(), **allan}


@dataclass(frozen=True)
class FittedCampaign:
    """Every DUT's channels fitted (by serial, then channel, in the parts' order), those that could not be, each
    with why, and how the campaign fell short of its plan ("" when it did not)."""

    fitted: dict[str, dict[str, FittedChannel]]
    uncalibrated: dict[str, dict[str, str]]
    partial: str
    dropped: dict[str, str]


def fit_channels(campaign: Campaign, options: FitOptions, where: str = "the campaign",
                 run_end: bool = False) -> FittedCampaign:
    """Fit and judge every channel of every DUT the early check kept; nothing is written. `where`: the campaign,
    as an error names it."""
    left_out = dropped(campaign.events)
    serials = [s for s in campaign.serials if s not in left_out]
    if not serials:
        raise ValueError(f"every DUT was dropped by the early check ({'; '.join(left_out.values())}): nothing to fit")
    jobs, uncalibrated = channel_jobs(campaign, serials, options)
    limits = recorded_acceptance(campaign.header.procedure_yaml, where)
    partial = partial_campaign(campaign, run_end)
    fitted: dict[str, dict[str, FittedChannel]] = {serial: {} for serial in serials}
    for job, outcome in zip(jobs, map_over_duts(bind(fit_job, options=options), jobs)):
        if isinstance(outcome, str):
            uncalibrated[job.serial][job.channel] = _stored(job.info) + outcome
            continue
        fitted[job.serial][job.channel] = FittedChannel(
            job.model, outcome, judge(job.model, job.channel, outcome, limits, partial), job.allan)
    return FittedCampaign(fitted, uncalibrated, partial, left_out)


def fit_campaign(campaign: Campaign, options: FitOptions,
                 source: dict[str, str], run_end: bool = False) -> tuple[CalibrationFile, dict[str, Any]]:
    """Fit every DUT of a stored campaign; the calibration file and the report `rig fit --json` prints
    (per serial: its verdict and each channel's figures). Nothing is written: the campaign's measurements are
    only read. `run_end`: the fit stage of the run itself, whose campaign is done but for the fit."""
    found = fit_channels(campaign, options, source.get("campaign", "the campaign"), run_end)
    duts, report = {}, {}
    for serial, channels in found.fitted.items():
        uncalibrated = found.uncalibrated[serial]
        if not channels:
            raise ValueError(f"sensor {serial}: no channel could be calibrated "
                             f"({'; '.join(f'{c}: {why}' for c, why in uncalibrated.items())})")
        duts[serial] = DutCalibration(channels={name: c.calibration() for name, c in channels.items()},
                                      not_calibrated=uncalibrated)
        overall = dut_verdict([(name, c.judgement) for name, c in channels.items()])
        report[serial] = {"verdict": overall.verdict, "verdict_reasons": overall.reasons,
                          "channels": {name: c.figures() for name, c in channels.items()},
                          **({"not_calibrated": uncalibrated} if uncalibrated else {})}
    calibration = CalibrationFile(
        format=CALIBRATION_FORMAT, format_version=CALIBRATION_VERSION, created=utc_now(),
        software_version=__version__, source={**source, **({"partial": found.partial} if found.partial else {})},
        duts=duts, dropped=found.dropped,
    )
    return calibration, report


def _stored(info: ChannelInfo) -> str:
    return f"{info.quantity} in {info.unit}: measured and stored; "


def dut_verdict(judgements: Sequence[tuple[str, Judgement]]) -> Judgement:
    """A DUT's verdict from its channels' (combined_verdict): when one fails, the failing channels' reasons;
    else every channel's. The part's first channel's reasons as they are, each other's marked with its name."""
    if len(judgements) == 1:
        return judgements[0][1]
    failed = any(j.verdict == "FAIL" for _, j in judgements)
    reasons = [reason if index == 0 else f"{name}: {reason}"
               for index, (name, j) in enumerate(judgements) if j.verdict == "FAIL" or not failed
               for reason in j.reasons]
    return Judgement(combined_verdict([j.verdict for _, j in judgements]), reasons)


def partial_campaign(campaign: Campaign, run_end: bool = False) -> str:
    """How a campaign fell short of its plan, or "" when every planned pose is stored (and it was not
    aborted: a run's own fit stage sees its campaign still running)."""
    stored, planned = len(campaign.poses), campaign.poses_planned
    state = "done" if run_end else campaign.state  # a run's own fit stage: its campaign is done but for the fit
    if stored >= planned and state != "aborted":
        return ""
    skipped = any(e.kind == "soak" and "setpoint skipped" in e.message for e in campaign.events)
    why = "a soak timed out and its setpoint was skipped" if skipped and state == "done" else f"state {state}"
    return f"partial campaign: {stored} of {planned} poses stored ({why})"


def fit_and_save(campaign: Campaign, campaign_path: Path, calibration_path: Path,
                 options: FitOptions, run_end: bool = False) -> tuple[CalibrationFile, dict[str, Any]]:
    """`fit_campaign`, then the calibration file written to `calibration_path` (replaced whole)."""
    if not campaign.poses:
        raise ValueError(f"{campaign_path}: no poses stored, nothing to fit")
    source = {"campaign": str(campaign_path), "measurements_sha256": measurements_sha256(campaign),
              "procedure": str(campaign.attrs.get("procedure_name", ""))}
    calibration, report = fit_campaign(campaign, options, source, run_end)
    save_calibration(calibration, calibration_path)
    return calibration, report


def summary_line(report: dict[str, Any], calibration_path: Path) -> str:
    """`calibration → cal.yaml: |g| RMSE 0.013 mg on verification poses (noise floor 0.012), …; 4 PASS` style:
    each quantity's phrase from its model (the worst of every DUT's), then the verdicts."""
    by_quantity: dict[str, tuple[ChannelModel, list[dict[str, Any]]]] = {}
    for dut in report.values():
        for figures in dut["channels"].values():
            model = model_for_quantity(figures["quantity"])
            if model is not None:
                by_quantity.setdefault(model.quantity, (model, []))[1].append(figures)
    figures = "; ".join(model.summary(found) for model, found in by_quantity.values())
    failed = [serial for serial, r in report.items() if r.get("verdict") == "FAIL"]
    unjudged = sum(r.get("verdict") == NOT_JUDGED for r in report.values())
    conditional = [serial for serial, r in report.items() if r.get("verdict") == "CONDITIONAL"]
    passed = len(report) - len(failed) - unjudged - len(conditional)
    verdicts = (f"{passed} PASS, {len(failed)} FAIL ({', '.join(failed)})" if failed else f"{passed} PASS")
    if conditional:  # inside a guard band: the procedure's decision rule states neither pass nor fail
        verdicts += f", {len(conditional)} CONDITIONAL ({', '.join(conditional)})"
    if unjudged:
        verdicts = (f"{unjudged} NOT JUDGED (no acceptance limits stated)" if unjudged == len(report)
                    else f"{verdicts}, {unjudged} NOT JUDGED")
    uncalibrated = sorted({channel for r in report.values() for channel in r.get("not_calibrated", {})})
    left = f"; not calibrated (measured and stored): {', '.join(uncalibrated)}" if uncalibrated else ""
    return f"calibration → {calibration_path}: {figures}, {len(report)} DUTs (worst of each); {verdicts}{left}"
