"""The early check's findings: a setpoint's figures (fit/setpoint_check.py) judged against the procedure's
limits, as the campaign's event log states them, and read back from it (the fit leaves out a dropped DUT,
`rig status` lists them). An event of kind `early_check` is the record: one line a person reads, one form
a program parses."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from accelcal_rig.fit.setpoint_check import SetpointFigures

#: The event kind the check's findings are logged (and notified) under.
EVENT_KIND = "early_check"
Action = Literal["warn", "drop"]
AXES = "xyz"


@dataclass(frozen=True)
class CheckLimits:
    residual_ratio: float      # residuals in units of their noise, √χ²_red
    direction_deg: float       # the mount's best rotation from the configured one
    axis_gain: float           # least response of an axis, g per g


@dataclass(frozen=True)
class Finding:
    """What the check found of one DUT at one setpoint: `finding` is `loose_mount`, `misoriented` or
    `dead_axis` (then `axis`), with its figure and the limit it passed."""

    serial: str
    setpoint_c: float
    finding: str
    value: float
    limit: float
    action: Action
    axis: str = ""

    def message(self) -> str:
        where = f"DUT {self.serial} at {self.setpoint_c:+g} °C: "
        what = {
            "loose_mount": f"residuals {self.value:.1f}× its noise (limit {self.limit:g}×): loose mount?",
            "misoriented": f"gravity {self.value:.1f}° from its mount's direction (limit {self.limit:g}°): "
                           "mounted in another orientation?",
            "dead_axis": f"axis {self.axis} responds {self.value:.3f} g/g (limit {self.limit:g} g/g): dead axis?",
        }[self.finding]
        return where + what + (DROPPED if self.action == "drop" else "")

    def as_dict(self) -> dict[str, Any]:
        return {"serial": self.serial, "setpoint_c": self.setpoint_c, "finding": self.finding, "value": self.value,
                "limit": self.limit, "action": self.action, **({"axis": self.axis} if self.axis else {})}


#: What a `drop` adds to its finding's line.
DROPPED = "; dropped: measured on, left out of the fit"


def findings(serials: Sequence[str], setpoint_c: float, figures: SetpointFigures, limits: CheckLimits,
             action: Action) -> list[Finding]:
    """Every figure beyond its limit, DUT by DUT in fixture order."""
    found = []
    for k, serial in enumerate(serials):
        ratio, direction = float(figures.residual_ratio[k]), float(figures.direction_deg[k])
        if ratio > limits.residual_ratio:
            found.append(Finding(serial, setpoint_c, "loose_mount", ratio, limits.residual_ratio, action))
        if np.isfinite(direction) and direction > limits.direction_deg:
            found.append(Finding(serial, setpoint_c, "misoriented", direction, limits.direction_deg, action))
        for axis, gain in zip(AXES, figures.axis_gain[k]):
            if gain < limits.axis_gain:
                found.append(Finding(serial, setpoint_c, "dead_axis", float(gain), limits.axis_gain, action, axis))
    return found


_NUMBER = r"[-+0-9.einf]+"
_PATTERNS = {
    "loose_mount": re.compile(rf"residuals (?P<value>{_NUMBER})× its noise \(limit (?P<limit>{_NUMBER})×\)"),
    "misoriented": re.compile(rf"gravity (?P<value>{_NUMBER})° from its mount's direction \(limit (?P<limit>{_NUMBER})°\)"),
    "dead_axis": re.compile(rf"axis (?P<axis>[xyz]) responds (?P<value>{_NUMBER}) g/g \(limit (?P<limit>{_NUMBER}) g/g\)"),
}
_WHERE = re.compile(rf"^DUT (?P<serial>\S+) at (?P<setpoint>{_NUMBER}) °C: (?P<rest>.*)$")


def parse(message: str) -> Finding | None:
    """The finding an `early_check` event's message states (None: not one)."""
    where = _WHERE.match(message)
    if where is None:
        return None
    for finding, pattern in _PATTERNS.items():
        found = pattern.match(where["rest"])
        if found is not None:
            try:
                return Finding(where["serial"], float(where["setpoint"]), finding, float(found["value"]),
                               float(found["limit"]), "drop" if message.endswith(DROPPED) else "warn",
                               found.groupdict().get("axis") or "")
            except ValueError:
                return None
    return None


def logged_findings(events: Iterable[Any]) -> list[Finding]:
    """The findings among a campaign's events (anything with `kind` and `message`), in the order logged."""
    return [f for e in events if e.kind == EVENT_KIND and (f := parse(e.message)) is not None]


def dropped(events: Iterable[Any]) -> dict[str, str]:
    """The DUTs the check dropped, each with why (its first finding that dropped it)."""
    reasons: dict[str, str] = {}
    for finding in logged_findings(events):
        if finding.action == "drop" and finding.serial not in reasons:
            reasons[finding.serial] = f"dropped by the early check: {finding.message().removesuffix(DROPPED)}"
    return reasons
