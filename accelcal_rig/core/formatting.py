"""Small text helpers shared by the engine's log, the CLI and the reports."""

from __future__ import annotations


def format_duration(seconds: float) -> str:
    """`50412.3` → `14:00:12` (hours may exceed 24)."""
    whole = int(round(seconds))
    return f"{whole // 3600:d}:{whole % 3600 // 60:02d}:{whole % 60:02d}"


def format_fixed(value: float, digits: int = 1) -> str:
    """`value` with `digits` decimals, never a negative zero: `-0.04` → `0.0` (a temperature just below zero
    rounds to zero, not to "−0.0 °C")."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text
