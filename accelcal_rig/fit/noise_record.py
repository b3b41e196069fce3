"""The still noise records of a campaign, read as one stream per setpoint and channel, and the Allan figures
of each axis: the random walk (a gyroscope's angle random walk, an accelerometer's velocity random walk) and
the bias instability, with their intervals (fit/allan.py).

A record is a run of consecutive blocks; between two blocks the store takes its moment, so the stream has
short gaps, stated with the figures (their share of the record) and ignored by the deviation.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from accelcal_rig.fit.allan import Estimate, allan_deviation, bias_instability, random_walk
from accelcal_rig.fit.channel_model import NoiseFigures
from accelcal_rig.store.content import Campaign

NOISE_KIND = "noise"
#: The record's figures are quoted at the setpoint nearest this (the data sheets' room temperature).
QUOTED_AT_C = 25.0


def noise_allan(campaign: Campaign, serial: str, channel: str, odr_hz: float,
                quoted_as: NoiseFigures) -> dict[str, Any] | None:
    """The Allan figures of one DUT's channel from the campaign's noise records (None: it has none), in the
    units its channel model quotes them (`quoted_as`): those of the record nearest 25 °C, and each setpoint's in
    `by_setpoint`."""
    plan = campaign.header.plan
    keys = campaign.pose_column("step_key")
    noise = np.isin(keys, list(plan.keys_of(NOISE_KIND)))
    if not noise.any():
        return None
    setpoints = campaign.pose_column("setpoint_c")
    values = campaign.channel_values(serial, channel)
    starts, ends = campaign.pose_column("t_start_s"), campaign.pose_column("t_end_s")
    by_setpoint = []
    for setpoint in dict.fromkeys(setpoints[noise].tolist()):
        rows = np.flatnonzero(noise & (setpoints == setpoint))
        rows = rows[np.argsort(starts[rows])]
        stream = values[rows].reshape(-1, values.shape[-1])
        span_s = float(ends[rows[-1]] - starts[rows[0]])
        gaps_s = float(np.sum(np.maximum(starts[rows[1:]] - ends[rows[:-1]], 0.0)))
        try:
            figures = axis_figures(stream, odr_hz, quoted_as)
        except ValueError as exc:
            figures = {"not_resolved": str(exc)}
        by_setpoint.append({"setpoint_c": float(setpoint), "samples": int(len(stream)), "duration_s": span_s,
                            "gaps_share": gaps_s / span_s if span_s > 0 else 0.0, **figures})
    quoted = min(by_setpoint, key=lambda row: abs(row["setpoint_c"] - QUOTED_AT_C))
    return {**quoted, "by_setpoint": by_setpoint}


def axis_figures(stream: np.ndarray, odr_hz: float, quoted_as: NoiseFigures) -> dict[str, Any]:
    """Per axis: the random walk and the bias instability with their 68 % intervals and averaging times."""
    curves = allan_deviation(stream, odr_hz)
    return {quoted_as.random_walk: [_scaled(random_walk(c), quoted_as.random_walk_factor) for c in curves],
            quoted_as.instability: [_scaled(bias_instability(c), quoted_as.instability_factor) for c in curves]}


def _scaled(estimate: Estimate, factor: float) -> dict[str, float]:
    return {"value": estimate.value * factor, "low": estimate.low * factor, "high": estimate.high * factor,
            "tau_s": estimate.tau_s, "confidence": estimate.confidence}
