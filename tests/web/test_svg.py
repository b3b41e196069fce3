"""The dashboard's plots read at a glance: round ticks that cover the data, a legend keyed by each series'
colour, and a line broken where a value is missing (a ramp polls the air, not the DUTs)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from accelcal_rig.web.svg import COLOURS, line_plot, nice_ticks


@pytest.mark.parametrize(("low", "high"), [(-0.37, 7.0), (-45.1, 63.2), (22.9, 23.1), (0.0, 0.003), (5.0, 5.0),
                                           (-40.0, 60.0), (0.0, 15.6)])
def test_ticks_are_round_and_cover_the_data(low: float, high: float) -> None:
    ticks = nice_ticks(low, high)
    step = ticks[1] - ticks[0]
    mantissa = step / 10.0 ** np.floor(np.log10(step))
    assert min(abs(mantissa - m) for m in (1.0, 2.0, 2.5, 5.0)) < 1e-6
    assert np.allclose(np.diff(ticks), step) and np.allclose(np.round(np.array(ticks) / step), np.array(ticks) / step)
    assert ticks[0] <= low and ticks[-1] >= high and 2 <= len(ticks) <= 7


def test_the_legend_is_keyed_and_a_missing_value_breaks_the_line() -> None:
    svg = line_plot([0.0, 1.0, 2.0, 3.0, 4.0], {"chamber air": [20.0, 21.0, 22.0, 23.0, 24.0],
                                                 "DUTs (mean)": [np.nan, np.nan, 21.5, np.nan, 23.5]},
                    "campaign time (h)", "°C")
    for colour, name in zip(COLOURS, ("chamber air", "DUTs (mean)")):
        assert re.search(rf'<line [^>]*stroke="{colour}"[^>]*class="key"/><text [^>]*>{re.escape(name)}</text>', svg)
    lines = re.findall(r'<polyline points="([^"]*)"', svg)
    assert len(lines) == 3 and [len(p.split()) for p in lines] == [5, 1, 1]  # the DUTs' line in two pieces
    assert "nan" not in svg
    assert re.findall(r'class="tick" text-anchor="middle">([^<]*)<', svg) == ["0", "1", "2", "3", "4"]
