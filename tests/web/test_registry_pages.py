"""The dashboard's registry pages tell dry runs from real calibrations (a `made` column, a filter) and show each
verdict in its own style: CONDITIONAL amber, apart from PASS and FAIL; a lot's CONDITIONAL stated beside its
yield; a serial's calibrations minutes apart state no drift per year."""

from __future__ import annotations

import re
from datetime import timedelta

import pytest
from starlette.testclient import TestClient

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.entries import campaign_entries
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app


@pytest.fixture(scope="module")
def registry(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A dry run's four calibrations, and a real CONDITIONAL one of another serial 12 minutes after a real PASS."""
    from accelcal_rig.assembly import run_campaign
    from accelcal_rig.engine.preparation import prepare
    from tests.conftest import REPO

    folder = tmp_path_factory.mktemp("registry-pages")
    campaign, calibration = folder / "quick.h5", folder / "quick.calibration.yaml"
    run_campaign(prepare(REPO / "procedures" / "quick-6pos.yaml"), campaign, dry_run=True, seed=0, overwrite=False,
                 calibration=calibration)
    dry = campaign_entries(campaign, calibration)
    judged = {"verdict_reasons": ["bias x at 25 °C against its limit"], "simulated": False, "serial": "REAL-1"}
    passed = dry[0] | judged | {"verdict": "PASS", "fit_sha256": "a" * 64}
    conditional = passed | {"verdict": "CONDITIONAL", "fit_sha256": "b" * 64,
                            "calibrated_at": passed["calibrated_at"] + timedelta(minutes=12)}
    url = normalised(str(folder / "registry.sqlite"))
    Registry.open(url).add([*dry, passed, conditional])
    return url


def _rows(page: str) -> list[str]:
    return re.findall(r'<tr class="(?:real|dry-run)">.*?</tr>', page, flags=re.S)


def test_the_registry_page_marks_and_filters_dry_runs(registry: str) -> None:
    client = TestClient(base_url="http://127.0.0.1", app=create_app([], registry))
    every = _rows(client.get("/registry").text)
    real = _rows(client.get("/registry", params={"made": "real"}).text)
    dry = _rows(client.get("/registry", params={"made": "dry-run"}).text)
    assert len(every) == len(real) + len(dry) and len(real) == 2 and len(dry) == 4
    assert all('class="made-dry-run">dry run<' in r for r in dry) and not any("dry run" in r for r in real)
    assert client.get("/registry", params={"made": "maybe"}).status_code == 400


def test_a_conditional_verdict_has_its_own_style(registry: str) -> None:
    client = TestClient(base_url="http://127.0.0.1", app=create_app([], registry))
    page = client.get("/registry/serials/REAL-1").text
    assert '<span class="verdict verdict-conditional">CONDITIONAL</span>' in page
    assert '<span class="verdict verdict-pass">PASS</span>' in page
    assert "not stated: the calibrations span 12 minutes" in page  # minutes apart: no drift per year
    lot = client.get("/registry/parts/adxl355").text
    assert '<span class="verdict verdict-conditional">1 CONDITIONAL</span>' in lot
    css = client.get("/static/dashboard.css").text
    assert re.search(r"\.verdict-conditional \{[^}]*background: #f2a900", css)
