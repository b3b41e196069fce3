"""A campaign before anything moves: both files loaded and checked against each other, the plan compiled,
and a schedule that cannot determine the fit it asks for refused."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from accelcal_rig.config.lab import Receipt
from accelcal_rig.config.load import (
    LoadedConfig,
    check_procedure_against_rig,
    load_procedure,
    load_rig,
    resolve_rig_path,
    with_chamber_profile,
    with_faults,
    with_part_ranges,
)
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.geometry import fixture_to_dut
from accelcal_rig.engine.references import REFERENCE_NEEDS, REFERENCES
from accelcal_rig.fit.acceptance import unknown_limit
from accelcal_rig.fit.channel_models import model_for_quantity
from accelcal_rig.fit.lm import DegenerateDesign, fit_sfem
from accelcal_rig.parts.registry import known_parts, part
from accelcal_rig.plan.compile import CooldownPoseMissing, Plan, VerificationSeenByFit, compile_plan
from accelcal_rig.plan.gyro_steps import NoRateAxis
from accelcal_rig.plan.kinematics import UnreachablePose
from accelcal_rig.store.space import StorageEstimate, estimate_storage


@dataclass(frozen=True)
class PreparedCampaign:
    """Both files validated against each other and the plan compiled: nothing has moved yet."""

    procedure: LoadedConfig[Procedure]
    rig: LoadedConfig[RigConfig]
    plan: Plan
    chamber_profile: str | None = None   # `--chamber-profile`: the rig's chamber swapped for this profile's
    #: `rig run --customer/--received/--condition`: what the campaign file records of every DUT whose fixture entry
    #: states none of its own.
    receipt: Receipt = Receipt()
    #: Where the command that starts the campaign writes its follow-up (the calibration, certificates, registry),
    #: recorded in the campaign for its resume: JSON the engine stores and does not read.
    follow_up: str = ""

    def storage(self, dry_run: bool) -> StorageEstimate:
        """The disk the campaign will take (a dry run also stores the simulation's truth)."""
        acquisition = self.procedure.model.acquisition
        sensors = self.rig.model.fixture.sensors
        channels = [[(c.name, len(c.axes)) for c in part(s.part).channels] for s in sensors]
        return estimate_storage(len(self.plan.pose_steps), len(sensors), acquisition.samples_per_pose,
                                len(self.plan.axis_names), dry_run, channels)


def prepare(procedure_path: Path, rig_override: Path | None = None, faults: str | None = None,
            chamber_profile: str | None = None) -> PreparedCampaign:
    """`faults`: fault injection for the simulators, `key=value,…` (see with_faults); `chamber_profile`: a
    dry run's chamber swapped for a built-in profile's (see with_chamber_profile)."""
    procedure = load_procedure(procedure_path)
    rig = with_chamber_profile(with_faults(load_rig(resolve_rig_path(procedure, rig_override)), faults),
                               chamber_profile)
    check_procedure_against_rig(procedure, rig)
    procedure = with_part_ranges(procedure, rig)
    _check_every_channel_has_a_reference(rig)
    _check_acceptance_is_judged(procedure, rig)
    try:
        plan = compile_plan(procedure.model, rig.model)
    except UnreachablePose as exc:
        raise procedure.error(("schedule",), f"{exc} (the turntable of {rig.path})") from None
    except CooldownPoseMissing as exc:
        raise procedure.error(("cooldown", "pose"), str(exc)) from None
    except VerificationSeenByFit as exc:
        raise procedure.error(("verify", "schedule"), str(exc)) from None
    except NoRateAxis as exc:
        raise procedure.error(("rates",), f"{exc} ({rig.path})") from None
    _check_design_identifies_fit(procedure, rig.model, plan)
    return PreparedCampaign(procedure, rig, plan, chamber_profile)


def _check_every_channel_has_a_reference(rig: LoadedConfig[RigConfig]) -> None:
    """Refuse, before anything moves, a part (a plug-in's) measuring a quantity no pose can say the reference
    of: the first pose would otherwise stop the campaign after its first soak."""
    for index, sensor in enumerate(rig.model.fixture.sensors):
        for channel in part(sensor.part).channels:
            if channel.quantity not in REFERENCES:
                raise rig.error(("fixture", "sensors", index, "part"),
                                f"the {part(sensor.part).label}'s {channel.name} channel measures {channel.quantity!r}, "
                                f"which no pose has a reference for (known: {', '.join(sorted(REFERENCES))})")
            key, what = REFERENCE_NEEDS.get(channel.quantity, ("", ""))
            if key and getattr(rig.model, key) is None:
                raise rig.error(("fixture", "sensors", index, "part"),
                                f"the {part(sensor.part).label}'s {channel.name} channel measures {channel.quantity}, "
                                f"whose reference at each pose is {what}: state {key} in {rig.path}")


def _check_acceptance_is_judged(procedure: LoadedConfig[Procedure], rig: LoadedConfig[RigConfig]) -> None:
    """Refuse a limit no channel model would judge (a misspelt key is a limit silently not judged): each channel's
    limits checked against its quantity's model, as the fixture's parts (else any known part) name the channel."""
    on_fixture = {c.name: c.quantity for s in rig.model.fixture.sensors for c in part(s.part).channels}
    anywhere = {c.name: c.quantity for p in known_parts().values() for c in p.channels}
    acceptance = procedure.model.acceptance
    for channel, limits in acceptance.channels.items():
        where: tuple[str, ...] = ("acceptance",) if _before_channels(procedure, channel) else ("acceptance", channel)
        quantity = on_fixture.get(channel, anywhere.get(channel))
        if quantity is None:
            raise procedure.error(where, f"no part has a channel {channel!r} (the parts' channels: "
                                         f"{', '.join(sorted(anywhere))})")
        model = model_for_quantity(quantity)
        if model is None:
            continue  # _check_every_channel_has_a_reference refused it on the fixture; elsewhere it judges nothing
        problem = unknown_limit(model, limits.figure_limits())
        if problem:
            raise procedure.error((*where, problem.split(" ", 1)[0]), problem)
        temperatures = procedure.model.verification_temperatures()
        for spec in model.limits:
            if spec.key in limits.figure_limits() and temperatures < spec.needs_temperatures:
                raise procedure.error((*where, spec.key), f"acceptance.{acceptance.written(channel, spec.key)} is judged "
                                      f"across verification temperatures: verify at "
                                      f"{_WORDS.get(spec.needs_temperatures, spec.needs_temperatures)} or more")
        if limits.parameters is not None:
            problem = unknown_limit(model, limits.parameters.limits(), parameters=True)
            if problem:
                raise procedure.error((*where, "parameters", problem.split(" ", 1)[0]), problem)


_WORDS = {2: "two", 3: "three"}


def _before_channels(procedure: LoadedConfig[Procedure], channel: str) -> bool:
    """Whether the channel's limits stand at the top of `acceptance`, as before limits were keyed by channel."""
    return (("acceptance", channel) not in procedure.lines
            and any(key[:1] == ("acceptance",) and len(key) == 2 for key in procedure.lines))


def _check_design_identifies_fit(procedure: LoadedConfig[Procedure], rig: RigConfig, plan: Plan) -> None:
    """Refuse, before a long campaign, a schedule that cannot determine the fit it asks for.

    A perfect sensor's readings at the planned poses, as each DUT's mount sees them, go through the same
    fit; a design the fit would refuse afterwards is refused now.
    """
    fit = procedure.model.fit
    if fit.mode == "none":
        return
    gravity_fixture = np.array([p.gravity_fixture for p in plan.poses])
    for sensor in rig.fixture.sensors:
        gravity = gravity_fixture @ fixture_to_dut(sensor.mount_euler_deg).T
        try:
            fit_sfem(gravity, np.full_like(gravity, 1e-5), gravity, fit.mode, fit.parameters)
        except DegenerateDesign as exc:
            raise procedure.error(("fit", "mode"), f"{exc} (sensor {sensor.serial}, {fit.parameters} parameters)") from None
