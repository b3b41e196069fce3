"""The decision rule (ILAC-G8:09/2019; ISO/IEC 17025:2017 §7.1.3, §7.8.6): how a figure and its expanded
uncertainty U (k = 2) are judged against a limit.

- **simple acceptance** (ILAC-G8 §4.2.1, shared risk): a figure inside its limit passes, outside fails; the
  uncertainty is stated beside it but does not move the decision.
- **guarded acceptance** (ILAC-G8 §4.2.2–4.2.3, non-binary): a guard band w = factor × U on both sides of the
  limit. A figure at least w inside it passes, at least w beyond it fails; in between the verdict is
  conditional — a conditional pass inside the limit, a conditional fail beyond it — because the
  uncertainty does not allow either to be stated with the confidence the rule asks.

Limits here are on magnitudes (|bias| ≤ L is −L ≤ bias ≤ L): a signed figure is judged by its magnitude and
stated with its sign.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Literal

Outcome = Literal["pass", "conditional pass", "conditional fail", "fail"]
Rule = Literal["simple", "guarded"]
#: How the outcomes of a sensor's limits make its verdict: the worst one decides.
_ORDER: dict[str, int] = {"pass": 0, "conditional pass": 1, "conditional fail": 2, "fail": 3}


@dataclass(frozen=True)
class DecisionRule:
    rule: Rule = "simple"
    #: guarded: the guard band in expanded uncertainties
    guard_band_factor: float = 1.0
    #: the procedure stated no rule: simple acceptance is applied and said so
    stated: bool = True

    def statement(self) -> str:
        """The rule as a certificate states it."""
        if self.rule == "simple":
            text = ("simple acceptance (ILAC-G8:09/2019 §4.2.1): a figure within its limit passes, beyond it fails; "
                    "the expanded uncertainty is stated but not taken into the decision (shared risk)")
        else:
            band = "U" if self.guard_band_factor == 1 else f"{self.guard_band_factor:g} × U"
            text = (f"guarded acceptance (ILAC-G8:09/2019 §4.2.2–4.2.3): a guard band w = {band} (expanded "
                    "uncertainty, k = 2) on each side of each limit; a figure at least w within its limit passes, "
                    "at least w beyond it fails, in between it is a conditional pass (within the limit) or a "
                    "conditional fail (beyond it)")
        return text + ("" if self.stated else "; the procedure states no rule, so simple acceptance applies")


@dataclass(frozen=True)
class LimitCheck:
    """One figure judged against one limit."""

    limit_key: str            # the procedure's key, e.g. "parameters.bias_mg"
    label: str                # what was judged, e.g. "bias y at 25 °C"
    value: float              # signed where the figure has a sign
    expanded_u: float | None  # U (k = 2) of the figure; None where none is stated
    limit: float
    unit: str
    outcome: Outcome
    #: a signed figure (a parameter, limit ±L) or a magnitude (an error figure, limit ≤ L)
    signed: bool = False

    def text(self) -> str:
        """One line: the figure with its sign, its U, the limit and the outcome."""
        u = f" ± {self.expanded_u:.2g}" if self.expanded_u is not None else ""
        value = f"{self.value:+.4g}" if self.signed else f"{self.value:.4g}"
        limit = f"±{self.limit:g}" if self.signed else f"≤ {self.limit:g}"
        return f"{self.label} {value}{u} {self.unit}, limit {limit} {self.unit}: {self.outcome}"

    def plain(self) -> dict[str, Any]:
        return asdict(self)


def decide(value: float, expanded_u: float | None, limit: float, rule: DecisionRule) -> Outcome:
    """The outcome of |value| against `limit` under `rule` (no uncertainty stated: no guard band)."""
    magnitude = abs(value)
    if rule.rule == "simple" or expanded_u is None:
        return "pass" if magnitude <= limit else "fail"
    band = rule.guard_band_factor * expanded_u
    if magnitude <= limit - band:
        return "pass"
    if magnitude > limit + band:
        return "fail"
    return "conditional pass" if magnitude <= limit else "conditional fail"


def check(limit_key: str, label: str, value: float, expanded_u: float | None, limit: float, unit: str,
          rule: DecisionRule, signed: bool = False) -> LimitCheck:
    if rule.rule == "guarded" and expanded_u is None:  # said, not hidden: this one is judged by its value alone
        label += " (no uncertainty stated: no guard band)"
    return LimitCheck(limit_key, label, float(value), None if expanded_u is None else float(expanded_u), float(limit),
                      unit, decide(value, expanded_u, limit, rule), signed)


def worst(checks: list[LimitCheck]) -> LimitCheck:
    """Of one limit's figures (each axis), the one that decides: the worst outcome, then the least margin."""
    def key(c: LimitCheck) -> tuple[int, float]:
        return _ORDER[c.outcome], abs(c.value) + (c.expanded_u or 0.0) - c.limit
    return max(checks, key=key)


def is_conditional(outcome: Outcome) -> bool:
    return outcome.startswith("conditional")


def failed(outcome: Outcome) -> bool:
    return outcome == "fail"
