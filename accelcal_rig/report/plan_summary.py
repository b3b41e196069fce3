"""`rig plan`: what a campaign will do and how long it will take, as text or one JSON object."""

from __future__ import annotations

from typing import Any

from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.formatting import format_duration
from accelcal_rig.engine.estimate import DurationEstimate
from accelcal_rig.engine.preparation import PreparedCampaign
from accelcal_rig.engine.step_ranges import FINE_RANGE_SHARE
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.parts.registry import part
from accelcal_rig.plan.compile import setpoint_label
from accelcal_rig.plan.steps import RateStep
from accelcal_rig.store.space import START_MARGIN, megabytes


def plan_lines(prepared: PreparedCampaign, estimate: DurationEstimate) -> list[str]:
    procedure, rig, plan = prepared.procedure.model, prepared.rig.model, prepared.plan
    soak = procedure.soak
    setpoints = plan.setpoints_c
    lines = [
        f"procedure  {procedure.name} ({prepared.procedure.path})",
        f"rig        {rig.name} ({prepared.rig.path}): chamber {rig.chamber.profile} over {rig.chamber.driver} "
        f"(ramp {rig.chamber.ramp_rate_c_per_min:g} °C/min, limits {rig.chamber.min_setpoint_c:g}…"
        f"{rig.chamber.max_setpoint_c:g} °C, safe {procedure.safe_setpoint_c or rig.chamber.safe_setpoint_c:g} °C), "
        f"turntable {len(rig.turntable.axes)} axes, {len(rig.fixture.sensors)} DUTs "
        f"({', '.join(s.serial for s in rig.fixture.sensors)})",
        f"setpoints  {len(setpoints)}, in this order: {', '.join(f'{s:g}' for s in setpoints)} °C",
        f"soak       at least {soak.min_dwell_min:g} min at setpoint, then {_soak_criterion(procedure)} with the "
        f"chamber within {soak.chamber_tolerance_c:g} °C; polled every {soak.poll_s:g} s; deadline "
        f"{soak.timeout_min:g} min ({soak.on_timeout})",
        _poses_line(prepared),
        *_gyroscope_lines(prepared),
        *_verification_lines(prepared),
        *_method_lines(prepared),
        "fit        none: measured only" if procedure.fit.mode == "none" else
        f"fit        {procedure.fit.mode}, {procedure.fit.parameters} parameters, polynomial degree "
        f"{procedure.fit.polynomial_degree}",
        *(f"warning    {w}" for w in plan_warnings(prepared)),
        _storage_line(prepared),
        "",
        "pose  " + " ".join(f"{name + ' °':>9s}" for name in plan.axis_names) + "   gravity in the fixture frame (g)",
    ]
    for pose in plan.poses:
        angles = " ".join(f"{a:9.3f}" for a in pose.angles_deg)
        gravity = " ".join(f"{g:+7.4f}" for g in pose.gravity_fixture)
        lines.append(f"{pose.number:4d}  {angles}   {gravity}")
    for pose in plan.verification_poses:
        angles = " ".join(f"{a:9.3f}" for a in pose.angles_deg)
        gravity = " ".join(f"{g:+7.4f}" for g in pose.gravity_fixture)
        lines.append(f"{'v' + str(pose.number):>4s}  {angles}   {gravity}")
    lines += ["", f"{'setpoint':>8s} {'ramp':>8s} {'soak':>8s} {'poses':>8s} {'ends at':>9s}  DUTs settle at (°C)"]
    t = 0.0
    for row in estimate.setpoints:
        t += row.total_s
        outcome = {"stable": "", "ramp": "  (poses while ramping)"}.get(
            row.soak_outcome, f"  {row.soak_outcome.upper()}: the campaign would stop")
        settled = ", ".join(f"{c:.2f}" for c in row.settled_dut_c)
        lines.append(f"{setpoint_label(row.setpoint_c):>8s} {format_duration(row.ramp_s):>8s} "
                     f"{format_duration(row.soak_s):>8s} {format_duration(row.poses_s):>8s} "
                     f"{format_duration(t):>9s}  {settled}{outcome}")
    lines += ["", f"estimated duration {format_duration(estimate.total_s)} (h:mm:ss; from the rig's ramp rate, "
                  "thermal time constants and axis speeds; instrument communication not included)",
              thermal_line(rig)]
    return lines


def thermal_line(rig: RigConfig) -> str:
    """Which thermal constants the estimate used: the rig's measured ones (`thermal:`), or defaults, named."""
    constants = rig.estimate_thermal()
    used = (f"heating {constants.heating_rate_c_per_min:.3g} °C/min, cooling {constants.cooling_rate_c_per_min:.3g} "
            "°C/min" + (f" (floor {constants.cooling_floor_c:.1f} °C)" if constants.cooling_floor_c is not None else "")
            + f", air lag {constants.chamber_time_constant_min:.3g} min, overshoot "
              f"{constants.chamber_overshoot_pct:.2g} %, fixture lag {constants.fixture_time_constant_min:.3g} min")
    if not constants.defaults:
        measured = f" ({rig.thermal.measured})" if rig.thermal.measured else ""
        return f"thermal    the rig's own{measured}: {used}"
    return (f"thermal    {used}; defaults for {', '.join(constants.defaults)} (the rig config's thermal: has none): "
            "measure them with rig characterise CAMPAIGN --write RIG")


def plan_warnings(prepared: PreparedCampaign) -> list[str]:
    """What the plan cannot give the fit it asks for: too few setpoints for the polynomial's degree."""
    procedure = prepared.procedure.model
    n, degree = len(procedure.setpoints_c), procedure.fit.polynomial_degree
    if procedure.fit.mode == "none" or procedure.cooldown is not None or n == 1:
        return []
    if n < degree + 1:
        return [f"{n} calibration setpoints cannot fix a degree-{degree} polynomial: the fit will use degree {n - 1}"]
    if n == degree + 1:
        return [f"{n} calibration setpoints for degree {degree}: the polynomial will interpolate them, with nothing "
                "left to check it (add setpoints, or verification setpoints)"]
    return []


def _storage_line(prepared: PreparedCampaign) -> str:
    storage = prepared.storage(dry_run=False)
    return (f"storage    about {megabytes(storage.journal_bytes)} journal + {megabytes(storage.file_bytes)} campaign "
            f"file; rig run starts with {megabytes(int(START_MARGIN * storage.need_bytes))} free ({START_MARGIN:g} × "
            f"the {megabytes(storage.need_bytes)} it needs at most, log and calibration included)")


def _poses_line(prepared: PreparedCampaign) -> str:
    procedure, plan = prepared.procedure.model, prepared.plan
    acquisition, cooldown = procedure.acquisition, procedure.cooldown
    fine = acquisition.fine_ranges
    ranges = ", ".join(f"{channel} ±{value:g}" + (f" (±{fine[channel]:g} at rest and up to {FINE_RANGE_SHARE * fine[channel]:g})"
                                                   if channel in fine else "")
                       for channel, value in acquisition.ranges.items())
    faster = {p.label: odr_hz_of(p, acquisition.odr_hz) for p in (part(s.part) for s in prepared.rig.model.fixture.sensors)
              if odr_hz_of(p, acquisition.odr_hz) != acquisition.odr_hz}
    rates = "".join(f" ({label} at {rate:g} Hz, its next rate above)" for label, rate in faster.items())
    samples = (f"{acquisition.samples_per_pose} samples at {acquisition.odr_hz:g} Hz{rates}, {ranges}, "
               f"settle {acquisition.settle_s:g} s")
    if cooldown is not None:
        return (f"records    {len(plan.pose_steps)} at pose {cooldown.pose} of the {procedure.schedule.kind} schedule, "
                f"every {cooldown.record_every_s:g} s for {cooldown.duration_min:g} min; {samples}")
    static = sum(1 for s in plan.pose_steps if s.stored_kind == "pose")
    return (f"poses      {len(plan.poses)} per setpoint ({procedure.schedule.kind}), {static} in all; {samples}"
            + (f"; {len(plan.pose_steps)} records in all with the rate steps and noise blocks" if len(plan.pose_steps) > static + _checks(plan)
               else ""))


def _checks(plan: Any) -> int:
    return sum(1 for s in plan.pose_steps if s.stored_kind == "verify")


def _earth_rate(latitude_deg: float | None, heading_deg: float | None) -> str:
    """What the gyroscope's reference does with the Earth's rate, as the rig config lets it (its certificate
    states the same)."""
    if latitude_deg is None:
        return ("the Earth's rate (up to 0.0042 °/s) is NOT taken out: the rig config states no latitude_deg, so it "
                "stays in every gyroscope's fitted bias (its certificate says so)")
    if heading_deg is None:
        return (f"vertical component at latitude {latitude_deg:g}° taken out; the horizontal one stays in the fitted "
                "bias (the rig config states no heading_deg)")
    return f"taken out at latitude {latitude_deg:g}° and table heading {heading_deg:g}°"


def _gyroscope_lines(prepared: PreparedCampaign) -> list[str]:
    """The rate steps and the noise record, where the procedure has them."""
    procedure, plan, rig = prepared.procedure.model, prepared.plan, prepared.rig.model
    lines = []
    rates = procedure.rates
    if rates is not None:
        turning = [s for s in plan.pose_steps if isinstance(s, RateStep)]
        by_axis: dict[int, list[str]] = {}
        for step in turning:
            if step.about not in by_axis.setdefault(step.rate_axis, []):
                by_axis[step.rate_axis].append(step.about)
        listed = ", ".join(f"±{r:g}" for r in rates.rates_dps)
        checked = (f"; verification ±{', ±'.join(f'{r:g}' for r in rates.verify_rates_dps)} °/s, never fitted"
                   if rates.verify_rates_dps else "")
        where = "; ".join(f"{', '.join(abouts)} on table axis {rig.turntable.axes[index].name} (reached at "
                          f"{rates.acceleration_dps2 or rig.turntable.axes[index].max_acceleration_dps2:g} °/s²)"
                          for index, abouts in by_axis.items()) or "no table axis"
        lines.append(f"rates      {listed} °/s about fixture {where}, held {rates.settle_s:g} s: "
                     f"{rates.steps_per_setpoint} per calibration setpoint, {len(turning)} in all{checked}")
        lines.append(f"earth      {_earth_rate(rig.latitude_deg, rig.heading_deg)}")
    if procedure.noise is not None:
        blocks = procedure.noise_blocks()
        block_s = procedure.acquisition.samples_per_pose / procedure.acquisition.odr_hz
        lines.append(f"noise      {blocks * block_s:g} s still at pose {procedure.noise.pose} per calibration setpoint "
                     f"({blocks} blocks of {procedure.acquisition.samples_per_pose} samples): the Allan deviation")
    return lines


def _verification_lines(prepared: PreparedCampaign) -> list[str]:
    procedure, plan = prepared.procedure.model, prepared.plan
    verify = procedure.verify
    if verify is None:
        return ["verify     none: every figure of the fit is in-sample (add a verify: section)"]
    every = ("at every calibration setpoint" if procedure.ramp is None or verify.on_ramp
             else "where the DUTs were soaked (at rest)")
    where = [w for w in (every if verify.at_setpoints else "",
                         "at " + ", ".join(f"{s:g}" for s in verify.setpoints_c) + " °C" if verify.setpoints_c else "")
             if w]
    total = sum(1 for s in plan.pose_steps if s.stored_kind == "verify")
    lines = [f"verify     {len(plan.verification_poses)} poses ({verify.schedule.kind}, listed as v1…) "
             f"{' and '.join(where)}: {total} in all, never fitted"]
    limits = procedure.acceptance
    judged = []
    for channel, stated in limits.channels.items():
        # Limits at the top of `acceptance` (the accelerometer's, as before they were keyed by channel) unprefixed.
        named = "" if limits.written(channel, "") == "" else f"{channel} "
        judged += [f"{named}{name} {value:g}" for name, value in stated.figure_limits().items()]
        if stated.parameters is not None:
            judged += [f"{named}{name} {value:g} at {stated.parameters.at_c:g} °C"
                       for name, value in stated.parameters.limits().items()]
    rule = ("" if not judged else f"; {limits.decision_rule} acceptance" + (
        f", guard band {limits.guard_band_factor:g} × U" if limits.decision_rule == "guarded" else "")
        if limits.decision_rule else "; simple acceptance (no decision_rule stated)")
    lines.append("accept     " + ("; ".join(judged) if judged else "no limits: every DUT NOT JUDGED (no statement of conformity)") +
                 rule + ("" if limits.allow_partial else "; a partial campaign fails"))
    return lines


def _soak_criterion(procedure: Any) -> str:
    soak = procedure.soak
    if soak.criterion == "settling":
        return (f"each DUT's fitted settling curve over {soak.window_min:g} min leaving at most {soak.settle_c:g} °C "
                f"to come and moving at most {soak.max_rate_c_per_min:g} °C/min (k = 2)")
    return f"each DUT within {soak.band_c:g} °C over {soak.window_min:g} min"


def _method_lines(prepared: PreparedCampaign) -> list[str]:
    procedure = prepared.procedure.model
    if procedure.cooldown is not None:
        how = ("switched off" if procedure.cooldown.chamber == "power-off"
               else f"set to {procedure.cooldown.ambient_c:g} °C")
        return [f"cool-down  after the soak at {procedure.setpoints_c[0]:g} °C the chamber is {how} and the DUTs "
                "cool while recording"]
    explained = method_explanation(procedure)
    return [f"method     {explained['name']}: {explained['how']}",
            f"           expected accurate because {explained['cancels']}",
            f"           not cancelled: {explained['does_not_cancel']}"]


def method_explanation(procedure: Any) -> dict[str, str]:
    """Which method a procedure uses, and the effects of a real rig it cancels and those it does not."""
    if procedure.ramp is None:
        return {
            "name": "soak",
            "how": "the DUTs soaked at every setpoint, its poses taken with the temperature held",
            "cancels": "every pose is taken with the DUTs settled: errors that follow the rate of temperature "
                       "change (package stress, the temperature sensor's lag behind the proof mass) vanish with "
                       "the rate; each DUT is fitted at its own sensor's temperature, so slot-to-slot "
                       "differences do not matter",
            "does_not_cancel": "hysteresis (the first setpoint is approached from one side, the rest from the "
                               "other: a step no polynomial follows, and nothing measures it); the slowest "
                               "method, every setpoint waits out the fixture's lag",
        }
    ramp = procedure.ramp
    last = procedure.setpoints_c[-1]
    if ramp.bidirectional:
        return {
            "name": "bidirectional ramp",
            "how": f"soak at {procedure.setpoints_c[0]:g} °C, the setpoint moved at {ramp.rate_c_per_min:g} °C/min to "
                   f"{last:g} °C (soaked there) and back, each band's poses on the way there and half-way between "
                   "on the way back, every pose fitted at its own temperature",
            "cancels": "each band is measured warming and cooling at the same rate: errors that follow the rate "
                       "of change change sign between the two and cancel in the joint fit to first order"
                       + ("; the fit's hysteresis and rate terms measure warming minus cooling and the bias per "
                          "°C/min, and the calibration is the sensor at rest" if procedure.fit.hysteresis else ""),
            "does_not_cancel": "what grows faster than the rate, and the two end bands, each approached from one "
                               "side; verification poses measured on the ramp carry its rate errors (the soaked "
                               "ends are at rest)",
        }
    return {
        "name": "ramp",
        "how": f"soak at {procedure.setpoints_c[0]:g} °C only, then the setpoint moves at {ramp.rate_c_per_min:g} "
               f"°C/min to {last:g} °C, poses taken as it goes (each setpoint's from half-way to it), every pose "
               "fitted at its own temperature",
        "cancels": "a slow ramp keeps errors that follow the rate of change small; each pose's own temperature "
                   "follows the drift through the band",
        "does_not_cancel": "errors that follow the rate of change are the same all along a one-way ramp and stay "
                           "in the bias (an offset in static use); hysteresis, one direction only, is not seen",
    }


def plan_json(prepared: PreparedCampaign, estimate: DurationEstimate) -> dict[str, Any]:
    procedure, plan = prepared.procedure.model, prepared.plan
    storage = prepared.storage(dry_run=False)
    return {
        "procedure": procedure.name, "procedure_path": str(prepared.procedure.path),
        "rig": prepared.rig.model.name, "rig_path": str(prepared.rig.path),
        "setpoints_c": list(plan.setpoints_c),
        "soak": procedure.soak.model_dump(), "acquisition": procedure.acquisition.model_dump(),
        **({"method": method_explanation(procedure)} if procedure.cooldown is None else {}),
        "axes": list(plan.axis_names),
        "poses": [{"number": p.number, "angles_deg": list(p.angles_deg), "gravity_fixture": list(p.gravity_fixture)}
                  for p in plan.poses],
        "verification_poses": [{"number": p.number, "angles_deg": list(p.angles_deg),
                                "gravity_fixture": list(p.gravity_fixture)} for p in plan.verification_poses],
        "poses_total": len(plan.pose_steps),
        "acceptance": procedure.acceptance.model_dump(),
        "warnings": plan_warnings(prepared),
        **({"earth_rate": _earth_rate(prepared.rig.model.latitude_deg, prepared.rig.model.heading_deg)}
           if procedure.rates is not None else {}),
        "storage": {"journal_bytes": storage.journal_bytes, "file_bytes": storage.file_bytes,
                    "need_bytes": storage.need_bytes, "start_free_bytes": int(START_MARGIN * storage.need_bytes)},
        "estimate": {
            "total_s": estimate.total_s,
            "thermal": {**{k: v for k, v in vars(prepared.rig.model.estimate_thermal()).items() if k != "defaults"},
                        "defaults": list(prepared.rig.model.estimate_thermal().defaults)},
            "setpoints": [{"setpoint_c": r.setpoint_c, "ramp_s": r.ramp_s, "soak_s": r.soak_s, "poses_s": r.poses_s,
                           "soak_outcome": r.soak_outcome, "settled_dut_c": list(r.settled_dut_c)}
                          for r in estimate.setpoints],
        },
    }
