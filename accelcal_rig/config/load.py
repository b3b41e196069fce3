"""Load and validate procedure and rig config files; every problem becomes `file:line: key: message`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Generic, TypeVar

from pydantic import BaseModel, ValidationError

from accelcal_rig.config.bounds import NUMBERS_FROM_TEXT
from accelcal_rig.config.procedure import BEFORE_RANGES, MAX_POLLS, Procedure
from accelcal_rig.config.rig import FaultInjection, RigConfig
from accelcal_rig.config.schedule import Schedule
from accelcal_rig.config.suggestions import explained
from accelcal_rig.config.yaml_lines import (
    CONFIG_LIMITS,
    KeyPath,
    YamlLimits,
    format_key,
    load_yaml_with_lines,
    locate,
    yaml_text_with_lines,
)
from accelcal_rig.errors import ConfigError
from accelcal_rig.parts.registry import part
from accelcal_rig.protocols.chamber_lines import LINE_PROFILES
from accelcal_rig.protocols.chamber_registers import PROFILES as REGISTER_PROFILES

ModelT = TypeVar("ModelT", bound=BaseModel)


@dataclass(frozen=True)
class LoadedConfig(Generic[ModelT]):
    """A validated model with the file it came from, so later checks can point at its lines."""

    model: ModelT
    path: Path
    text: str
    lines: dict[KeyPath, int]

    def error(self, key_path: KeyPath, message: str) -> ConfigError:
        """A ConfigError naming this file, the key, and its line (its nearest parent's if left to default)."""
        _, line = locate(self.lines, key_path)
        return ConfigError(f"{self.path}:{line}: {format_key(key_path)}: {message}")


def load_validated(path: Path, model: type[ModelT], limits: YamlLimits = CONFIG_LIMITS,
                   relocate: Callable[[KeyPath, dict[KeyPath, int]], KeyPath] | None = None) -> LoadedConfig[ModelT]:
    """Parse and validate any of the project's YAML files; an error is one line, `file:line: key: message`
    for the first problem, with how many more there are (fix one, run again). `relocate`: where in the file
    a key of the model stands, for a model that reads an older layout into its own."""
    data, lines, text = load_yaml_with_lines(path, limits)
    return _validated(path, model, data, lines, text, relocate)


#: What stands in for a section a rig config leaves out for `rig check --only`: never connected, only there
#: so the rest validates (and a dry run's simulated lab has something to hold).
_STAND_INS: dict[str, dict[str, Any]] = {
    "chamber": {},
    "turntable": {"axes": [{"name": "stand-in", "axis": [0, 0, 1]}]},
    "fixture": {"sensors": [{"serial": "STAND-IN"}]},
}
#: The section of a rig config each instrument of `rig check --only` needs.
SECTION_OF = {"chamber": "chamber", "turntable": "turntable", "sensors": "fixture"}


def load_rig_for_check(path: Path, only: frozenset[str]) -> LoadedConfig[RigConfig]:
    """A rig config that may leave out the sections of the instruments `rig check --only` does not check."""
    data, lines, text = load_yaml_with_lines(path)
    needed = {SECTION_OF[name] for name in only}
    for section, stand_in in _STAND_INS.items():
        if section not in data:
            if section in needed:
                raise ConfigError(f"{path}:1: {section}: missing, and --only checks it")
            data[section] = stand_in
    return _validated(path, RigConfig, data, lines, text)


def _validated(path: Path, model: type[ModelT], data: Any, lines: dict[KeyPath, int], text: str,
               relocate: Callable[[KeyPath, dict[KeyPath, int]], KeyPath] | None = None) -> LoadedConfig[ModelT]:
    try:
        validated = model.model_validate(data)
    except ValidationError as exc:
        messages = []
        for err in exc.errors(include_url=False):
            key = tuple(err["loc"])
            shown, line = locate(lines, relocate(key, lines) if relocate is not None else key)
            message = explained(model, data, err) or str(err["msg"]).removeprefix("Value error, ")
            messages.append(f"{path}:{line}: {format_key(shown)}: {message}")
        more = (f" (and {len(messages) - 1} more problem{'s' if len(messages) > 2 else ''})" if len(messages) > 1 else "")
        raise ConfigError(messages[0] + more) from None
    return LoadedConfig(validated, path, text, lines)


def load_procedure(path: Path) -> LoadedConfig[Procedure]:
    return load_validated(path, Procedure)


def load_rig(path: Path) -> LoadedConfig[RigConfig]:
    return load_validated(path, RigConfig)


def validate_rig_text(text: str, path: Path) -> LoadedConfig[RigConfig]:
    """The rig config `text` would be at `path` (a rewrite checked before it replaces the file)."""
    data, lines, text = yaml_text_with_lines(text, path)
    return _validated(path, RigConfig, data, lines, text)


def resolve_rig_path(procedure: LoadedConfig[Procedure], override: Path | None) -> Path:
    """The rig config to use: `--config` if given, else the procedure's `rig`, relative to the procedure."""
    if override is not None:
        return override
    path = (procedure.path.parent / procedure.model.rig).resolve()
    if not path.is_file():
        raise procedure.error(("rig",), f"{path}: no such rig config (it is relative to the procedure's folder)")
    return path


#: What a rate step turns: the quantity of the channels whose range its rates must be inside.
RATE_QUANTITY = "angular rate"


def _range_key(procedure: LoadedConfig[Procedure], channel: str) -> KeyPath:
    """Where a channel's range is in the procedure: `acquisition.ranges.<channel>`, or the key that gave it before
    ranges were keyed by channel (`range_g`, `range_dps`)."""
    for key, named in BEFORE_RANGES.items():
        if named == channel and ("acquisition", key) in procedure.lines:
            return ("acquisition", key)
    return ("acquisition", "ranges", channel)


def with_part_ranges(procedure: LoadedConfig[Procedure], rig: LoadedConfig[RigConfig]) -> LoadedConfig[Procedure]:
    """The procedure with each fixture channel's range the procedure leaves unset at its part's default
    (`Channel.default_range`): what the campaign configures, records and reports."""
    acquisition = procedure.model.acquisition
    defaults = {c.name: c.default_range for s in rig.model.fixture.sensors for c in part(s.part).channels
                if c.name not in acquisition.ranges and c.default_range is not None}
    if not defaults:
        return procedure
    ranges = {**acquisition.ranges, **defaults}
    model = procedure.model.model_copy(update={"acquisition": acquisition.model_copy(update={"ranges": ranges})})
    return replace(procedure, model=model)


def check_procedure_against_rig(procedure: LoadedConfig[Procedure], rig: LoadedConfig[RigConfig]) -> None:
    """Cross-file checks that neither file can make alone: setpoints and angles inside the rig's limits, the
    range and data rate among those of every DUT's part."""
    chamber = rig.model.chamber
    acquisition = procedure.model.acquisition
    ranges = acquisition.ranges
    for sensor in rig.model.fixture.sensors:
        dut_part = part(sensor.part)
        for channel in dut_part.channels:  # every channel of every DUT's part needs its range, and one it has
            key = _range_key(procedure, channel.name)
            range_ = ranges.get(channel.name, channel.default_range)
            if range_ is None:
                raise procedure.error(key, f"not set: sensor {sensor.serial} of {rig.path} is an "
                                                             f"{dut_part.label}, whose {channel.name} channel needs "
                                                             f"its ± full scale in {channel.unit}")
            problem = channel.range_problem(range_, dut_part.label)
            if problem:
                raise procedure.error(key, f"{problem}: sensor {sensor.serial} of {rig.path}")
        problem = dut_part.rate_problem(acquisition.odr_hz)
        if problem:
            raise procedure.error(("acquisition", "odr_hz"), f"{problem}: sensor {sensor.serial} of {rig.path}")
        gyroscope_steps = [k for k in ("rates", "noise") if getattr(procedure.model, k) is not None]
        gyroscopes = [c for c in dut_part.channels if c.quantity == RATE_QUANTITY]
        if gyroscope_steps and not gyroscopes:
            raise procedure.error((gyroscope_steps[0],), f"sensor {sensor.serial} of {rig.path} is an "
                                                         f"{dut_part.label}, which has no gyroscope")
        for name, fine in acquisition.fine_ranges.items():
            finer = next((c for c in dut_part.channels if c.name == name), None)
            key = ("acquisition", "fine_ranges", name)
            if finer is None or finer.quantity != RATE_QUANTITY:
                raise procedure.error(key, f"sensor {sensor.serial} of {rig.path} is an {dut_part.label}, which has no "
                                           f"{name} channel that measures {RATE_QUANTITY} (a finer range is for a "
                                           "gyroscope's steps at rest and at low rates)")
            problem = finer.range_problem(fine, dut_part.label)
            if problem:
                raise procedure.error(key, f"{problem}: sensor {sensor.serial} of {rig.path}")
            if not fine < ranges.get(name, finer.default_range or 0.0):
                raise procedure.error(key, f"±{fine:g} {finer.unit} is not finer than the channel's range "
                                           f"(acquisition ranges.{name} ±{ranges.get(name, finer.default_range)} "
                                           f"{finer.unit})")
        rates = procedure.model.rates
        for channel in gyroscopes if rates is not None else ():
            assert rates is not None
            beyond = [r for r in (*rates.rates_dps, *rates.verify_rates_dps) if r >= ranges[channel.name]]
            if beyond:
                raise procedure.error(("rates", "rates_dps"), f"{max(beyond):g} °/s is not inside the gyroscope's "
                                      f"range (acquisition ranges.{channel.name} ±{ranges[channel.name]:g} °/s)")
    for index, setpoint in enumerate(procedure.model.setpoints_c):
        if not chamber.min_setpoint_c <= setpoint <= chamber.max_setpoint_c:
            raise procedure.error(
                ("setpoints_c", index),
                f"{setpoint:g} °C is outside the chamber limits {chamber.min_setpoint_c:g}…"
                f"{chamber.max_setpoint_c:g} °C of {rig.path}",
            )
    safe = procedure.model.safe_setpoint_c
    if safe is not None and not chamber.min_setpoint_c <= safe <= chamber.max_setpoint_c:
        raise procedure.error(("safe_setpoint_c",), f"{safe:g} °C is outside the chamber limits of {rig.path}")
    polls = worst_case_polls(procedure.model, rig.model)
    if polls > MAX_POLLS:
        raise procedure.error(("soak",), f"its ramp and soak deadlines allow {polls:.0f} temperature polls at "
                                         f"poll_s {procedure.model.soak.poll_s:g} s with the chamber of {rig.path} "
                                         f"(at most {MAX_POLLS}): poll less often or shorten the deadlines")
    ramp = procedure.model.ramp
    if ramp is not None and ramp.rate_c_per_min > chamber.ramp_rate_c_per_min:
        raise procedure.error(("ramp", "rate_c_per_min"), f"{ramp.rate_c_per_min:g} °C/min is faster than the chamber "
                                                          f"of {rig.path} ramps ({chamber.ramp_rate_c_per_min:g} °C/min)")
    cooldown = procedure.model.cooldown
    if cooldown is not None and cooldown.chamber == "power-off" and chamber.register_map().power_register is None:
        raise procedure.error(("cooldown", "chamber"), f"the chamber of {rig.path} has no power event in its register "
                                                       "map to switch it off: use chamber: ambient")
    verify = procedure.model.verify
    schedules: list[tuple[KeyPath, Schedule]] = [(("schedule",), procedure.model.schedule)]
    if verify is not None:
        schedules.append((("verify", "schedule"), verify.schedule))
    for where, schedule in schedules:
        if schedule.kind != "explicit":
            continue
        axes = rig.model.turntable.axes
        for pose, angles in enumerate(schedule.angles_deg):
            if len(angles) != len(axes):
                raise procedure.error(
                    (*where, "angles_deg", pose),
                    f"{len(angles)} angles given, the turntable of {rig.path} has {len(axes)} axes",
                )
            for axis, angle in zip(axes, angles):
                if not axis.allows(angle):
                    raise procedure.error(
                        (*where, "angles_deg", pose),
                        f"axis {axis.name} angle {angle:g}° is outside its limits {axis.min_deg:g}…{axis.max_deg:g}°",
                    )


def worst_case_polls(procedure: Procedure, rig: RigConfig) -> float:
    """Temperature polls the campaign makes if every ramp and soak runs to its deadline (the plan's duration
    estimate plays them, so this bounds its work)."""
    soak = procedure.soak
    previous = rig.simulation.ambient_c
    polls = 0.0
    for setpoint in procedure.setpoints_c:
        ramp_s = soak.ramp_timeout_factor * abs(setpoint - previous) / (rig.chamber.ramp_rate_c_per_min / 60.0)
        polls += (ramp_s + soak.ramp_timeout_margin_min * 60.0 + soak.timeout_min * 60.0) / soak.poll_s
        previous = setpoint
    return polls


def swap_chamber_profile(rig: RigConfig, profile: str) -> RigConfig:
    """The rig with its chamber replaced by a simulated one of a built-in profile (its own driver, no endpoint,
    none of the old profile's register overrides)."""
    known = sorted({*REGISTER_PROFILES, *LINE_PROFILES})
    if profile not in known:
        raise ConfigError(f"--chamber-profile: {profile!r} is not a chamber profile (known: {', '.join(known)})")
    driver = "line" if profile in LINE_PROFILES else "modbus-tcp"
    chamber = rig.chamber.model_copy(update={"profile": profile, "driver": driver, "registers": {},
                                             "protocol_overrides": {}, "endpoint": None, "options": {}})
    return rig.model_copy(update={"chamber": chamber})


def with_chamber_profile(rig: LoadedConfig[RigConfig], profile: str | None) -> LoadedConfig[RigConfig]:
    """`--chamber-profile`: a dry run (or `rig sim`) with the configured chamber swapped for that profile's."""
    return rig if not profile else replace(rig, model=swap_chamber_profile(rig.model, profile))


def with_faults(rig: LoadedConfig[RigConfig], spec: str | None) -> LoadedConfig[RigConfig]:
    """The rig with `simulation.faults` keys set from the command line: `rate=0.05,kinds=drop+corrupt`."""
    if not spec:
        return rig
    faults = rig.model.simulation.faults.model_dump()
    for item in spec.split(","):
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not sep or key not in faults:
            raise ConfigError(f"--faults: {item.strip()!r}: expected key=value with key one of {', '.join(faults)}")
        faults[key] = value.split("+") if key == "kinds" else (None if value in ("", "none") else value)
    try:  # the command line's values are text: its numbers are read from it (a file's must be numbers)
        validated = FaultInjection.model_validate(faults, context={NUMBERS_FROM_TEXT: True})
    except ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        raise ConfigError(f"--faults: {format_key(tuple(err['loc']))}: {err['msg']}") from None
    simulation = rig.model.simulation.model_copy(update={"faults": validated})
    return replace(rig, model=rig.model.model_copy(update={"simulation": simulation}))
