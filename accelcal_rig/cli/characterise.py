"""`rig characterise CAMPAIGN [--write RIG]`: the rig's thermal constants fitted to a finished campaign's ramps
and soaks (analysis/thermal_constants.py), checked against the campaign itself — how long it took beside what
its estimate said, with the constants it ran with and with the fitted ones — and, on a dry run, against the
simulator's own constants; written into the rig config's `thermal:` section on request."""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from accelcal_rig.analysis.thermal_constants import ThermalConstants, fit_thermal_constants
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig, RigThermal
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.engine.estimate import estimate_duration
from accelcal_rig.errors import ConfigError
from accelcal_rig.plan.compile import compile_plan
from accelcal_rig.store.read import load_campaign


@dataclass(frozen=True)
class Characterised:
    campaign: Path
    constants: ThermalConstants
    rig: RigConfig
    dry_run: bool
    #: The campaign's duration and its estimates (with the constants it ran with, with the fitted ones); None
    #: where the campaign is not complete (nothing to compare).
    took_s: float | None
    estimated_then_s: float | None
    estimated_now_s: float | None

    def thermal(self) -> dict[str, float | None]:
        """The fitted constants as the rig config's `thermal:` keys."""
        return _fitted(self.constants)

    def measured(self) -> str:
        return f"rig characterise {self.campaign.name} on {dt.date.today().isoformat()}"


def characterise(campaign: Path) -> Characterised:
    """Fit the campaign's ramps and soaks; compare its duration with its estimates (a complete campaign)."""
    stored = load_campaign(campaign)
    try:
        constants = fit_thermal_constants(stored.soaks, stored.serials)
    except ValueError as exc:
        raise ConfigError(f"{campaign}: {exc}") from None
    try:
        rig = RigConfig.model_validate(parse_yaml_text(stored.header.rig_yaml, f"{campaign}: its rig config"))
        procedure = Procedure.model_validate(parse_yaml_text(stored.header.procedure_yaml,
                                                             f"{campaign}: its procedure"))
    except ValidationError as exc:  # a file from another version whose configs this one reads otherwise
        first = exc.errors(include_url=False)[0]
        raise ConfigError(f"{campaign}: its stored configs no longer validate ({'.'.join(map(str, first['loc']))}: "
                          f"{first['msg']})") from None
    took = then = now = None
    if stored.state == "done" and len(stored.poses) == stored.poses_planned and stored.run_count == 1:
        plan = compile_plan(procedure, rig)
        took = max(pose.t_end_s for pose in stored.poses)
        then = estimate_duration(procedure, rig, plan).total_s
        fitted = RigThermal.model_validate({**_fitted(constants), "measured": None})
        now = estimate_duration(procedure, replace_thermal(rig, fitted), plan).total_s
    return Characterised(campaign, constants, rig, bool(stored.attrs.get("dry_run", False)), took, then, now)


def _fitted(constants: ThermalConstants) -> dict[str, float | None]:
    chamber = constants.chamber
    return {"heating_rate_c_per_min": chamber.heating_rate_c_per_min,
            "cooling_rate_c_per_min": chamber.cooling_rate_c_per_min, "cooling_floor_c": chamber.cooling_floor_c,
            "room_c": chamber.room_c, "chamber_time_constant_min": chamber.chamber_time_constant_min,
            "chamber_overshoot_pct": chamber.chamber_overshoot_pct,
            "fixture_time_constant_min": constants.fixture_time_constant_min}


def replace_thermal(rig: RigConfig, thermal: RigThermal) -> RigConfig:
    return rig.model_copy(update={"thermal": thermal})


def characterise_lines(result: Characterised) -> list[str]:
    """What `rig characterise` prints: each constant, beside the simulator's on a dry run; the fit's residuals;
    the campaign's duration against its estimates."""
    chamber, sim = result.constants.chamber, result.rig.simulation if result.dry_run else None
    commanded = result.rig.chamber.ramp_rate_c_per_min

    def simulated(text: str) -> str:
        return f"   (the simulator's: {text})" if sim is not None else ""

    def rate(value: float | None, what: str) -> str:
        return f"{value:.2f} °C/min" if value is not None else f"not measured (no {what} ramp)"

    duts = result.constants.duts
    lines = [
        f"campaign   {result.campaign}: {chamber.n_points} air polls over its ramps and soaks (room "
        f"{chamber.room_c:.1f} °C)",
        f"heating    {rate(chamber.heating_rate_c_per_min, 'heating')}{simulated(f'{commanded:g}')}",
        f"cooling    {rate(chamber.cooling_rate_c_per_min, 'cooling')} at room temperature, "
        + (f"slowing towards {chamber.cooling_floor_c:.1f} °C" if chamber.cooling_floor_c is not None
           else "not slowing with temperature")
        + simulated(f"{commanded:g}" + (f", floor {sim.cooling_floor_c:g} °C" if sim and sim.cooling_floor_c is not None
                                        else ", no floor")),
        f"air lag    {chamber.chamber_time_constant_min:.2f} min{simulated(f'{sim.chamber_time_constant_min:g}' if sim else '')}",
        f"overshoot  {chamber.chamber_overshoot_pct:.2f} %{simulated(f'{sim.chamber_overshoot_pct:g}' if sim else '')}",
        f"fixture    {result.constants.fixture_time_constant_min:.2f} min, the slowest DUT's (each: "
        + ", ".join(f"{d.serial} {d.time_constant_min:.2f}" for d in duts) + ")"
        + (simulated(", ".join(f"{tau_s / 60:.2f}" for tau_s in sim.fixture_time_constants_s([d.serial for d in duts])))
           if sim else ""),
        f"residual   air {chamber.residual_rms_c:.3f} °C RMS; DUTs {min(d.residual_rms_c for d in duts):.3f} … "
        f"{max(d.residual_rms_c for d in duts):.3f} °C RMS",
    ]
    if result.took_s is None:
        lines.append("estimate   not compared: the campaign did not run whole in one run")
    else:
        assert result.estimated_then_s is not None and result.estimated_now_s is not None
        lines.append(f"estimate   the campaign took {format_duration(result.took_s)}; its estimate with the constants it "
                     f"ran with {format_duration(result.estimated_then_s)} ({_off(result.estimated_then_s, result.took_s)}), "
                     f"with these {format_duration(result.estimated_now_s)} ({_off(result.estimated_now_s, result.took_s)})")
    return lines


def _off(estimate_s: float, took_s: float) -> str:
    return f"{100.0 * (estimate_s - took_s) / took_s:+.1f} %"


def characterise_json(result: Characterised) -> dict[str, Any]:
    chamber = result.constants.chamber
    return {"campaign": str(result.campaign), "thermal": result.thermal(),
            "duts": [{"serial": d.serial, "time_constant_min": d.time_constant_min, "gain": d.gain,
                      "offset_c": d.offset_c, "residual_rms_c": d.residual_rms_c} for d in result.constants.duts],
            "air_residual_rms_c": chamber.residual_rms_c, "air_polls": chamber.n_points,
            "took_s": result.took_s, "estimated_then_s": result.estimated_then_s,
            "estimated_now_s": result.estimated_now_s}
