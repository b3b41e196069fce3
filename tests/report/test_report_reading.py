"""The report reads as it should: the campaign's facts without an empty header row, event times never broken
inside a timestamp, no "−0.0", the DUTs during every pose in the soak traces (the verification-only setpoints'
too), the |g| figure naming the gravity it used, and the uncertainty caption's reading figures those of every
DUT (their range), not one DUT's quoted for all."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.core.formatting import format_fixed
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.report import figures
from accelcal_rig.report.campaign_data import read_campaign_data
from accelcal_rig.report.html_report import _reading_of, write_report


@pytest.fixture(scope="module")
def page(paper_campaign: Path, tmp_path_factory: pytest.TempPathFactory) -> str:
    return write_report(paper_campaign, tmp_path_factory.mktemp("report") / "report").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def data(paper_campaign: Path):  # noqa: ANN201 - CampaignData
    return read_campaign_data(paper_campaign)


def test_the_campaign_table_has_no_empty_header_row(page: str) -> None:
    campaign = page.split("<h2>Campaign</h2>")[1].split("</table>")[0].strip()
    assert not re.search(r"<th[ >]", campaign) and campaign.startswith('<table><tr><td class="text">state</td>')


def test_event_times_are_never_wrapped_inside_a_timestamp(page: str, data) -> None:
    log = page.split("<h2>Event log</h2>")[1]
    shown = [e for e in data.events if e.level != "debug"]
    times = re.findall(r'<td class="text unbroken">([^<]*)</td><td class="text unbroken">([^<]*)</td>', log)
    assert [wall for _, wall in times] == [e.wall_time for e in shown]
    assert re.search(r"td\.unbroken \{ white-space: nowrap; \}", page)


def test_no_negative_zero_is_printed(page: str) -> None:
    text = re.sub(r"<[^>]+>", " ", page)
    assert not re.search(r"(?<![\d.])[-−]0\.0+(?![\d])", text)
    assert format_fixed(-0.04) == "0.0" and format_fixed(-0.06) == "-0.1" and format_fixed(-0.004, 2) == "0.00"


def test_the_soak_traces_show_the_duts_at_every_verification_only_setpoint(data, tmp_path: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    drawn = []
    monkeypatch.setattr(figures, "save", lambda figure, path: drawn.append(figure) or path)
    figures.soak_traces(data, data.soak_band_c, tmp_path / "soaks.png")
    top = drawn[0].axes[0]
    verification_t_h = np.concatenate([line.get_xdata() for line in top.get_lines()
                                       if line.get_marker() == "o" and len(line.get_xdata())])
    calibration = {float(s) for d in data.duts.values() for s in d.poses.setpoint_c}
    verification_only = [soak for soak in data.soaks if soak.setpoint_c not in calibration]
    assert verification_only  # the paper campaign verifies between its calibration setpoints
    for soak in verification_only:
        after = soak.t_reached_s / 3600.0
        assert np.any((verification_t_h > after) & (verification_t_h < after + 2.0)), soak.label
    labels = [text.get_text() for text in top.get_legend().get_texts()]
    assert "DUTs during verification poses" in labels


def test_the_norm_figure_names_the_gravity_it_used(data, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    drawn = []
    monkeypatch.setattr(figures, "save", lambda figure, path: drawn.append(figure) or path)
    figures.norm_deviation(data, tmp_path / "norm.png")
    title = drawn[0].get_suptitle()
    assert data.gravity_m_s2 == STANDARD_GRAVITY_M_S2  # the simulated rig states no site gravity
    assert title.endswith(f"g: the standard {STANDARD_GRAVITY_M_S2} m/s² (the site's was not stated)")
    assert figures.gravity_used(9.8123) == "the site's 9.8123 m/s²"


def test_the_uncertainty_caption_gives_every_duts_reading_figures(page: str, data) -> None:
    budgets = [d.fit.figures["uncertainty_budget"] for d in data.duts.values() if d.fit is not None]
    stderr = [v for b in budgets for v in b["reading_stderr_mg"]]
    temperature = [b["temperature_u_c"] for b in budgets]
    assert len({round(v, 4) for v in stderr}) > 1  # the DUTs differ: one DUT's figures would not be all's
    expected = (f"standard error {min(stderr):.4f} … {max(stderr):.4f} mg per axis), its temperature read like a "
                f"pose&#x27;s (±{min(temperature):.3f} … {max(temperature):.3f} °C) (the range over the "
                f"{len(budgets)} DUTs)")
    assert expected in page
    one = _reading_of(budgets[:1])
    assert "range" not in one and f"{budgets[0]['reading_stderr_mg'][0]:.4f}" in one
