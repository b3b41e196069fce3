"""Small line plots as inline SVG: the dashboard draws its own (no plotting library, no script, no network)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from html import escape

import numpy as np

_WIDTH, _HEIGHT, _LEFT, _BOTTOM, _TOP, _RIGHT = 720, 260, 56, 34, 12, 12
COLOURS = ("#1f6feb", "#d1242f", "#1a7f37", "#8250df", "#bf8700")
MARKER_COLOUR, GAP_COLOUR = "#57606a", "#d0d7de"
#: A legend entry's width; marker labels closer than this to the one before are stacked above it.
_KEY_W, _LABEL_W = 150, 44


@dataclass(frozen=True)
class Marker:
    """A moment marked across the plot: a dashed vertical line at `x` labelled `label`, and, when `since` is
    before it, the span since then shaded (a time nothing was recorded)."""

    x: float
    label: str
    since: float | None = None


def line_plot(x: list[float], series: dict[str, list[float]], x_label: str, y_label: str,
              markers: Sequence[Marker] = (), marker_key: str = "", gap_key: str = "") -> str:
    """One SVG element: each series a line against `x` (broken where a value is missing: NaN), with round ticks
    and a legend keyed by each series' colour; `markers` drawn over them, keyed in the legend as `marker_key`
    (their shaded spans as `gap_key`); empty data says so."""
    if not x:
        return f'<p class="empty">no {escape(y_label)} yet</p>'
    xs = np.asarray([*x, *(m.x for m in markers)], dtype=float)
    ys = np.concatenate([np.asarray(v, dtype=float) for v in series.values()])
    x_ticks, y_ticks = nice_ticks(*_finite_span(xs)), nice_ticks(*_finite_span(ys))
    x0, x1, y0, y1 = x_ticks[0], x_ticks[-1], y_ticks[0], y_ticks[-1]
    plot_w, plot_h = _WIDTH - _LEFT - _RIGHT, _HEIGHT - _TOP - _BOTTOM

    def px(v: np.ndarray) -> np.ndarray:
        return _LEFT + (v - x0) / (x1 - x0) * plot_w

    def py(v: np.ndarray) -> np.ndarray:
        return _TOP + (1.0 - (v - y0) / (y1 - y0)) * plot_h

    parts = [f'<svg class="plot" viewBox="0 0 {_WIDTH} {_HEIGHT}" role="img" aria-label="{escape(y_label)}">',
             f'<rect x="{_LEFT}" y="{_TOP}" width="{plot_w}" height="{plot_h}" class="frame"/>']
    for tick in x_ticks:
        parts.append(f'<text x="{px(np.array(tick)):.1f}" y="{_HEIGHT - 16}" class="tick" text-anchor="middle">'
                     f'{_tick_text(tick, x_ticks)}</text>')
    for tick in y_ticks:
        parts.append(f'<text x="{_LEFT - 6}" y="{py(np.array(tick)) + 4:.1f}" class="tick" text-anchor="end">'
                     f'{_tick_text(tick, y_ticks)}</text>')
    parts.append(f'<text x="{_LEFT + plot_w / 2}" y="{_HEIGHT - 2}" class="label" text-anchor="middle">'
                 f'{escape(x_label)}</text>')
    parts.append(f'<text x="12" y="{_TOP + plot_h / 2}" class="label" text-anchor="middle" '
                 f'transform="rotate(-90 12 {_TOP + plot_h / 2})">{escape(y_label)}</text>')
    spans = [m for m in markers if m.since is not None and m.since < m.x]
    for m in spans:  # under the data: a gap is where there is none
        left = float(px(np.array(m.since)))
        parts.append(f'<rect x="{left:.1f}" y="{_TOP}" width="{max(float(px(np.array(m.x))) - left, 1.0):.1f}" '
                     f'height="{plot_h}" fill="{GAP_COLOUR}" class="gap"/>')
    xs = xs[:len(x)]
    gaps = [(m.since, m.x) for m in spans if m.since is not None]
    for k, (name, values) in enumerate(series.items()):
        colour = COLOURS[k % len(COLOURS)]
        broken_x, broken_y = _broken_across(xs, np.asarray(values, dtype=float), gaps)
        for run in _runs(px(broken_x), py(broken_y)):
            points = " ".join(f"{a:.1f},{b:.1f}" for a, b in run)
            parts.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        key_x = _LEFT + 8 + _KEY_W * k
        parts.append(f'<line x1="{key_x}" y1="{_TOP + 10}" x2="{key_x + 18}" y2="{_TOP + 10}" stroke="{colour}" '
                     f'stroke-width="3" class="key"/>')
        parts.append(f'<text x="{key_x + 24}" y="{_TOP + 14}" class="legend">{escape(name)}</text>')
    parts += _markers(markers, [float(v) for v in px(np.array([m.x for m in markers], dtype=float))], plot_h)
    key_x = _LEFT + 8 + _KEY_W * len(series)
    if markers and marker_key:
        parts.append(f'<line x1="{key_x}" y1="{_TOP + 10}" x2="{key_x + 18}" y2="{_TOP + 10}" stroke="{MARKER_COLOUR}" '
                     f'stroke-width="2" stroke-dasharray="4 3" class="key"/>')
        parts.append(f'<text x="{key_x + 24}" y="{_TOP + 14}" class="legend">{escape(marker_key)}</text>')
        key_x += _KEY_W
    if spans and gap_key:
        parts.append(f'<rect x="{key_x}" y="{_TOP + 5}" width="18" height="10" fill="{GAP_COLOUR}" class="key"/>')
        parts.append(f'<text x="{key_x + 24}" y="{_TOP + 14}" class="legend">{escape(gap_key)}</text>')
    parts.append("</svg>")
    return "".join(parts)


def _markers(markers: Sequence[Marker], at: list[float], plot_h: float) -> list[str]:
    """Each marker's dashed line and its label at the foot of the plot, beside the line (stacked upwards when
    the one before is too close to read apart)."""
    parts, last_x, level = [], float("-inf"), 0
    for marker, x in sorted(zip(markers, at), key=lambda pair: pair[1]):
        level = level + 1 if x - last_x < _LABEL_W else 0
        last_x = x
        parts.append(f'<line x1="{x:.1f}" y1="{_TOP}" x2="{x:.1f}" y2="{_TOP + plot_h}" stroke="{MARKER_COLOUR}" '
                     f'stroke-width="1.5" stroke-dasharray="4 3" class="marker"/>')
        right = x > _WIDTH - _RIGHT - _LABEL_W  # near the right edge: the label left of its line
        parts.append(f'<text x="{x - 3 if right else x + 3:.1f}" y="{_TOP + plot_h - 5 - 13 * level:.1f}" '
                     f'class="marker-label" text-anchor="{"end" if right else "start"}">{escape(marker.label)}</text>')
    return parts


def nice_ticks(low: float, high: float, most: int = 7) -> list[float]:
    """Round ticks covering low…high: a step of 1, 2, 2.5 or 5 × 10^k, at most `most` ticks, the first at or
    below `low` and the last at or above `high` (the axis runs between them)."""
    if high - low < 1e-9:
        low, high = low - 0.5, high + 0.5
    for power in range(int(np.floor(np.log10(high - low))) - 1, 12):
        for mantissa in (1.0, 2.0, 2.5, 5.0):
            step = mantissa * 10.0 ** power
            first, last = np.floor(low / step + 1e-9) * step, np.ceil(high / step - 1e-9) * step
            if round((last - first) / step) + 1 <= most:
                return [round(float(first + i * step), 10) for i in range(int(round((last - first) / step)) + 1)]
    return [low, high]


def _tick_text(tick: float, ticks: list[float]) -> str:
    """A tick as few digits as its step needs (`-40`, `2.5`, `0`)."""
    step = abs(ticks[1] - ticks[0]) if len(ticks) > 1 else 1.0
    decimals = max(0, -int(np.floor(np.log10(step) + 1e-9))) if step < 1 else 0
    text = f"{tick:.{decimals + (1 if round(step * 10 ** decimals, 6) % 1 else 0)}f}"
    return "0" if float(text) == 0 else text


def _broken_across(xs: np.ndarray, ys: np.ndarray,
                   gaps: list[tuple[float, float]]) -> tuple[np.ndarray, np.ndarray]:
    """The points with a missing one (NaN) put between two neighbours that straddle a gap: no line is drawn
    across a time nothing was recorded."""
    straddles = np.zeros(max(len(xs) - 1, 0), dtype=bool)
    for since, until in gaps:
        straddles |= (xs[:-1] <= since) & (xs[1:] >= until)
    rows = np.flatnonzero(straddles) + 1
    return np.insert(xs, rows, np.nan), np.insert(ys, rows, np.nan)


def _runs(xs: np.ndarray, ys: np.ndarray) -> list[list[tuple[float, float]]]:
    """The points in runs without a missing value: a line is broken where one is (NaN)."""
    runs: list[list[tuple[float, float]]] = [[]]
    for a, b in zip(xs, ys):
        if np.isfinite(a) and np.isfinite(b):
            runs[-1].append((float(a), float(b)))
        elif runs[-1]:
            runs.append([])
    return [run for run in runs if run]


def _finite_span(values: np.ndarray) -> tuple[float, float]:
    finite = values[np.isfinite(values)]
    return (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
