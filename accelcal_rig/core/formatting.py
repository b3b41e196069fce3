"""Small text helpers shared by the engine's log, the CLI and the reports."""

from __future__ import annotations


def format_duration(seconds: float) -> str:
    """`50412.3` → `14:00:12` (hours may exceed 24)."""
    whole = int(round(seconds))
    return f"{whole // 3600:d}:{whole % 3600 // 60:02d}:{whole % 60:02d}"
