"""The early check after a setpoint's calibration poses: each DUT not dropped against its own fit of them
(fit/setpoint_check.py), each finding a warning event of kind `early_check` (the log, `rig status`, the
notifications) and, with `early_check.action: drop`, the DUT left out of the fit. A dropped DUT is still
acquired: every pose of the campaign file holds every DUT (its columns), and its data so far stays."""

from __future__ import annotations

import numpy as np

from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.run_context import RunContext
from accelcal_rig.engine.step_handler import StepHandler
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.early_check import EVENT_KIND, CheckLimits, findings, logged_findings
from accelcal_rig.fit.setpoint_check import SetpointFigures, design_determined, setpoint_figures
from accelcal_rig.plan.steps import CheckSetpoint
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.records import PoseRecord


class CheckSetpointStep:
    def run(self, step: CheckSetpoint, run: RunContext) -> None:
        check_setpoint(step, run)

    def estimate(self, step: CheckSetpoint, played: PlayedRig) -> None:
        """Arithmetic on stored poses: no time on the rig."""


def check_setpoint(step: CheckSetpoint, run: RunContext) -> None:
    """Judge every DUT still in the campaign on the setpoint's stored calibration poses; log what it finds."""
    settings = run.procedure.early_check
    if settings.action == "none":
        return
    campaign = run.writer.campaign
    calibration_keys = campaign.header.plan.keys_of("pose")
    poses = [p for p in campaign.poses if p.setpoint_c == step.setpoint_c and p.step_key in calibration_keys]
    where = f"early check at {step.setpoint_c:+g} °C"
    checked = {serial: channel for serial in campaign.serials if (channel := checked_channel(campaign, serial))}
    indices = [k for k, serial in enumerate(campaign.serials) if serial not in run.dropped and serial in checked
               and checked[serial] in poses[0].duts[k].channels] if poses else []
    if not indices:
        return
    channels = [checked[campaign.serials[k]] for k in indices]
    mean_g, stderr_g, reference_g = (_stacked(poses, indices, channels, name) for name in ("mean", "stderr", "reference"))
    if not design_determined(reference_g[0]):
        run.events.info(EVENT_KIND, f"{where}: not possible, the {len(poses)} poses do not determine each DUT's "
                                    "own fit (directions too few or all near one plane)")
        return
    limits = CheckLimits(settings.residual_ratio_limit, settings.direction_limit_deg, settings.axis_gain_limit)
    figures = setpoint_figures(mean_g, stderr_g, reference_g, np.radians(run.rig.turntable.accuracy_arcsec / 3600.0),
                               limits.axis_gain)
    serials = [campaign.serials[k] for k in indices]
    found = findings(serials, step.setpoint_c, figures, limits, settings.action if settings.action == "drop" else "warn")
    logged = {(f.serial, f.setpoint_c, f.finding, f.axis) for f in logged_findings(campaign.events)}
    for finding in found:
        if (finding.serial, finding.setpoint_c, finding.finding, finding.axis) in logged:
            continue  # a resumed run checking a setpoint again: said once
        run.events.warning(EVENT_KIND, finding.message())
        run.report.notify(EVENT_KIND, finding.message())
    if settings.action == "drop":
        run.dropped.update(f.serial for f in found)
    run.events.info(EVENT_KIND, f"{where}: {summary(figures, limits)}; {len({f.serial for f in found})} of "
                                f"{len(serials)} DUTs flagged")


def checked_channel(campaign: Campaign, serial: str) -> str | None:
    """The DUT's channel the check judges: its first whose channel model has a check of each setpoint (an
    accelerometer's, against gravity); None where it has none."""
    for info in campaign.header.dut_channels(serial):
        model = model_for_quantity(info.quantity)
        if model is not None and model.setpoint_check:
            return info.name
    return None


def _stacked(poses: list[PoseRecord], indices: list[int], channels: list[str], name: str) -> np.ndarray:
    """One field of each DUT's checked channel, (D, n, 3): the DUTs at `indices` over the poses."""
    return np.array([[getattr(p.duts[k].channels[channel], name) for p in poses] for k, channel in zip(indices, channels)],
                    dtype=float)


def summary(figures: SetpointFigures, limits: CheckLimits) -> str:
    """The figures' spread over the DUTs beside their limits: what the check computed, flagged or not."""
    directions = figures.direction_deg[np.isfinite(figures.direction_deg)]
    mount = (f"mount within {directions.min():.2f}…{directions.max():.2f}° (limit {limits.direction_deg:g}°)"
             if directions.size else "mount not judged (a dead axis)")
    return (f"residuals {figures.residual_ratio.min():.2f}…{figures.residual_ratio.max():.2f}× their noise (limit "
            f"{limits.residual_ratio:g}×), {mount}, axes respond {figures.axis_gain.min():.3f}…"
            f"{figures.axis_gain.max():.3f} g/g (limit {limits.axis_gain:g})")


CHECK_SETPOINT: StepHandler[CheckSetpoint] = CheckSetpointStep()
