"""Where a campaign's follow-up goes, as its `rig run` recorded it in the campaign (the `follow_up` attribute:
follow_up.FollowUp as JSON), for the commands that finish or judge a campaign and for the dashboard."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


def recorded_follow_up(attrs: dict[str, Any]) -> dict[str, Any]:
    """What the campaign's run recorded; empty for a campaign from before it was recorded, or a damaged record."""
    try:
        stored = json.loads(str(attrs.get("follow_up") or "{}"))
    except ValueError:
        return {}
    return stored if isinstance(stored, dict) else {}


def recorded_calibration(attrs: dict[str, Any], campaign: Path) -> Path:
    """The campaign's calibration file: where its run was told to write it, else beside the campaign."""
    stored = recorded_follow_up(attrs).get("calibration")
    return Path(stored) if isinstance(stored, str) and stored else campaign.with_suffix(".calibration.yaml")
