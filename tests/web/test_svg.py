"""The dashboard's plots read at a glance: round ticks that cover the data, a legend keyed by each series'
colour, and a line broken where a value is missing (a ramp polls the air, not the DUTs)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from accelcal_rig.web.svg import COLOURS, Marker, line_plot, nice_ticks


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


def test_a_marker_is_a_keyed_dashed_line_its_gap_shaded_and_close_labels_stacked() -> None:
    """A resume at 2 h after 1 h down, another a moment later, one past the data's end: each a dashed line with
    its label, the down time shaded under the data, both keyed; the axis reaches the last marker."""
    svg = line_plot([0.0, 1.0, 2.0, 3.0], {"chamber air": [20.0, 21.0, 22.0, 23.0]}, "campaign time (h)", "°C",
                    markers=[Marker(2.0, "run 2", since=1.0), Marker(2.05, "run 3"), Marker(6.0, "run 4")],
                    marker_key="resumed", gap_key="rig down")
    lines = re.findall(r'<line x1="([\d.]+)" y1="[\d.]+" x2="[\d.]+" y2="[\d.]+" [^>]*stroke-dasharray[^>]*class="marker"/>', svg)
    labels = re.findall(r'<text x="([\d.]+)" y="([\d.]+)" class="marker-label" text-anchor="(\w+)">([^<]*)</text>', svg)
    assert len(lines) == 3 and [label[3] for label in labels] == ["run 2", "run 3", "run 4"]
    assert labels[0][1] != labels[1][1] and labels[0][1] == labels[2][1]  # the close one stacked above
    assert labels[2][2] == "end"  # at the right edge: the label left of its line
    gap = re.search(r'<rect x="([\d.]+)" y="[\d.]+" width="([\d.]+)" height="[\d.]+" fill="[^"]+" class="gap"/>', svg)
    assert gap and abs(float(gap[1]) + float(gap[2]) - float(lines[0])) < 0.2
    assert svg.index('class="gap"') < svg.index("<polyline")  # under the data
    assert [len(p.split()) for p in re.findall(r'<polyline points="([^"]*)"', svg)] == [2, 2]  # not across the gap
    assert re.search(r'stroke-dasharray="4 3" class="key"/><text [^>]*>resumed</text>', svg)
    assert re.search(r'class="key"/><text [^>]*>rig down</text>', svg)
    assert re.findall(r'class="tick" text-anchor="middle">([^<]*)<', svg)[-1] == "6"


def test_without_markers_nothing_of_them_is_drawn() -> None:
    svg = line_plot([0.0, 1.0], {"a": [1.0, 2.0]}, "x", "y", marker_key="resumed", gap_key="rig down")
    assert "marker" not in svg and "gap" not in svg and "resumed" not in svg and "rig down" not in svg
