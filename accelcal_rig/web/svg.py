"""Small line plots as inline SVG: the dashboard draws its own (no plotting library, no script, no network)."""

from __future__ import annotations

from html import escape

import numpy as np

_WIDTH, _HEIGHT, _LEFT, _BOTTOM, _TOP, _RIGHT = 720, 260, 56, 34, 12, 12
COLOURS = ("#1f6feb", "#d1242f", "#1a7f37", "#8250df", "#bf8700")


def line_plot(x: list[float], series: dict[str, list[float]], x_label: str, y_label: str) -> str:
    """One SVG element: each series a polyline against `x`, with ticks and a legend; empty data says so."""
    if not x:
        return f'<p class="empty">no {escape(y_label)} yet</p>'
    xs = np.asarray(x, dtype=float)
    ys = np.concatenate([np.asarray(v, dtype=float) for v in series.values()])
    x0, x1 = _span(xs.min(), xs.max())
    y0, y1 = _span(np.nanmin(ys), np.nanmax(ys))
    plot_w, plot_h = _WIDTH - _LEFT - _RIGHT, _HEIGHT - _TOP - _BOTTOM

    def px(v: np.ndarray) -> np.ndarray:
        return _LEFT + (v - x0) / (x1 - x0) * plot_w

    def py(v: np.ndarray) -> np.ndarray:
        return _TOP + (1.0 - (v - y0) / (y1 - y0)) * plot_h

    parts = [f'<svg class="plot" viewBox="0 0 {_WIDTH} {_HEIGHT}" role="img" aria-label="{escape(y_label)}">',
             f'<rect x="{_LEFT}" y="{_TOP}" width="{plot_w}" height="{plot_h}" class="frame"/>']
    for tick in np.linspace(x0, x1, 6):
        parts.append(f'<text x="{px(np.array(tick)):.1f}" y="{_HEIGHT - 16}" class="tick" text-anchor="middle">'
                     f'{tick:.3g}</text>')
    for tick in np.linspace(y0, y1, 5):
        parts.append(f'<text x="{_LEFT - 6}" y="{py(np.array(tick)) + 4:.1f}" class="tick" text-anchor="end">'
                     f'{tick:.3g}</text>')
    parts.append(f'<text x="{_LEFT + plot_w / 2}" y="{_HEIGHT - 2}" class="label" text-anchor="middle">'
                 f'{escape(x_label)}</text>')
    parts.append(f'<text x="12" y="{_TOP + plot_h / 2}" class="label" text-anchor="middle" '
                 f'transform="rotate(-90 12 {_TOP + plot_h / 2})">{escape(y_label)}</text>')
    for k, (name, values) in enumerate(series.items()):
        colour = COLOURS[k % len(COLOURS)]
        points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(px(xs), py(np.asarray(values, dtype=float))))
        parts.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        parts.append(f'<text x="{_LEFT + 8 + 130 * k}" y="{_TOP + 14}" class="legend" fill="{colour}">'
                     f'{escape(name)}</text>')
    parts.append("</svg>")
    return "".join(parts)


def _span(low: float, high: float) -> tuple[float, float]:
    if not np.isfinite(low) or not np.isfinite(high):
        return 0.0, 1.0
    if high - low < 1e-9:
        return low - 0.5, high + 0.5
    margin = 0.05 * (high - low)
    return low - margin, high + margin
