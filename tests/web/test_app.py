"""The dashboard's pages and JSON over HTTP (Starlette's test client): campaigns with their progress,
temperatures, warnings and certificates, the registry by serial and by part, the token, and files outside
the watched folders never served."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from accelcal_rig.registry.database import Registry
from accelcal_rig.registry.location import normalised
from accelcal_rig.web.app import create_app


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """A folder with one finished dry run (its certificates beside it) and a registry holding it."""
    from accelcal_rig.cli import main
    from tests.conftest import REPO

    folder = tmp_path_factory.mktemp("campaigns")
    registry = normalised(str(folder / "registry.sqlite"))
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--dry-run", "-o", str(folder / "quick.h5"),
                 "-q", "--no-pdf", "--registry", registry]) == 0
    return folder, registry


def test_the_front_page_lists_the_campaign_and_its_duts(lab) -> None:
    folder, registry = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry))
    page = client.get("/")
    assert page.status_code == 200 and 'data-name="quick.h5"' in page.text
    assert "ADX355-A001, ADX355-A002, ADX355-A003, ADX355-A004" in page.text and "12/12" in page.text
    assert '<script src="/static/dashboard.js"' in page.text and "http" not in page.text.split("<body>")[0]
    assert client.get("/static/dashboard.js").status_code == 200
    rows = client.get("/api/campaigns").json()
    assert [(r["name"], r["state"], r["poses_done"]) for r in rows] == [("quick.h5", "done", 12)]


def test_a_campaign_page_has_its_plot_warnings_and_certificates(lab) -> None:
    folder, registry = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry))
    page = client.get("/campaigns/quick.h5")
    assert page.status_code == 200 and "<svg" in page.text and "chamber air" in page.text
    assert "ADX355-A001.DRAFT.html" in page.text and "DRAFT, not issued" in page.text
    certificate = client.get("/campaigns/quick.h5/certificates/ADX355-A001.DRAFT.html")
    assert certificate.status_code == 200 and "ADX355-A001" in certificate.text
    assert certificate.headers["content-security-policy"] == "sandbox"  # its scripts cannot reach the dashboard
    assert client.get("/campaigns/quick.h5/certificates/..%2Fquick.h5.journal").status_code == 404  # exists, outside
    assert client.get("/campaigns/nothing.h5").status_code == 404


def test_the_registry_by_serial_and_by_part(lab) -> None:
    folder, registry = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry))
    search = client.get("/registry", params={"serial": "ADX355-A003"}, follow_redirects=False)
    assert search.status_code == 303 and search.headers["location"] == "/registry/serials/ADX355-A003"
    page = client.get("/registry/serials/ADX355-A003")
    assert page.status_code == 200 and "valid calibration" in page.text
    assert 'id="no-trend"' in page.text and "No trend yet: one calibration" in page.text   # not an empty plot
    assert 'id="valid"' in page.text  # what scripts and the browser test find the valid calibration by
    assert 'id="history"' in page.text
    lot = client.get("/registry/parts/adxl355")
    assert lot.status_code == 200 and "4 sensors" in lot.text
    assert "no calibration of NOBODY" in client.get("/registry/serials/NOBODY").text


def test_with_a_token_nothing_is_served_without_it(lab) -> None:
    folder, registry = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry, token="s3cret"))
    assert client.get("/").status_code == 401 and client.get("/api/campaigns").status_code == 401
    assert client.get("/", params={"token": "wrong"}).status_code == 401
    assert client.get("/", params={"token": "s3cret"}).status_code == 200  # and a cookie from now on
    assert client.get("/api/campaigns").status_code == 200
    bearer = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry, token="s3cret"))
    assert bearer.get("/api/campaigns", headers={"Authorization": "Bearer s3cret"}).status_code == 200


def test_a_damaged_campaign_file_is_listed_as_such(lab, tmp_path: Path) -> None:
    folder, registry = lab
    shutil.copy(folder / "quick.h5", tmp_path / "good.h5")
    (tmp_path / "broken.h5").write_bytes(b"not a campaign")
    rows = {r["name"]: r for r in TestClient(base_url="http://127.0.0.1", app=create_app([tmp_path], registry)).get("/api/campaigns").json()}
    assert rows["good.h5"]["state"] == "done"
    assert rows["broken.h5"]["state"] == "unreadable" and rows["broken.h5"]["error"]
    assert Registry.open(registry).count() == 4  # reading campaigns leaves the registry as it was


def test_without_a_token_only_loopback_names_are_answered(lab) -> None:
    """A page elsewhere pointing a name of its own at 127.0.0.1 (DNS rebinding) gets nothing."""
    folder, registry = lab
    client = TestClient(base_url="http://evil.example", app=create_app([folder], registry))
    assert client.get("/api/campaigns").status_code == 400


def test_a_token_of_any_text_is_compared_and_a_serial_of_any_text_is_a_path(lab) -> None:
    folder, registry = lab
    client = TestClient(base_url="http://127.0.0.1", app=create_app([folder], registry, token="s3cret"))
    assert client.get("/", params={"token": "é"}).status_code == 401  # not a crash
    client.get("/", params={"token": "s3cret"})
    redirect = client.get("/registry", params={"serial": "S/N#1"}, follow_redirects=False)
    assert redirect.headers["location"] == "/registry/serials/S%2FN%231"
    assert "no calibration of S/N#1" in client.get(redirect.headers["location"]).text


def test_rig_serve_refuses_an_open_address_without_a_token(capsys) -> None:
    from accelcal_rig.cli import main

    assert main(["serve", "--host", "0.0.0.0"]) == 2
    assert "off 127.0.0.1 the dashboard needs --token" in capsys.readouterr().err


def test_a_campaign_whose_writer_has_ended_is_not_shown_as_live_from_the_cache(lab, monkeypatch) -> None:
    """A run killed changes no file: the campaign shown as run by a live process is read again once no process
    holds it, and no longer shown live."""
    from accelcal_rig.web import campaigns as module

    folder, _ = lab
    real = module.campaign_status
    holding = {"now": True}

    def status(path: Path, campaign) -> dict:  # noqa: ANN001 - as the module calls it
        found = real(path, campaign)
        alive = holding["now"]
        return {**found, "state": "running", "writer": "alive (pid 4242)" if alive else "gone (pid 4242 ended)",
                "progress": {"line": "T30 soak"} if alive else None}

    monkeypatch.setattr(module, "campaign_status", status)
    monkeypatch.setattr(module, "holder", lambda path: "pid 4242" if holding["now"] else None)
    folders = module.CampaignFolders([folder])
    assert folders.summary("quick.h5")["progress"] == {"line": "T30 soak", "left": None, "now": "T30 soak"}
    holding["now"] = False  # killed: no file changed
    summary = folders.summary("quick.h5")
    assert summary["progress"] is None and summary["writer"].startswith("gone")


def test_a_campaigns_retries_are_grouped_by_instrument_with_count_times_and_outcome(tmp_path: Path) -> None:
    """Faults in 3 % of replies: the page has one row per instrument and kind of trouble, not a line per
    attempt, each saying it recovered (the campaign went on to the end)."""
    from accelcal_rig.cli import main
    from accelcal_rig.store.read import load_campaign
    from tests.conftest import REPO

    campaign = tmp_path / "lossy.h5"
    assert main(["run", str(REPO / "procedures" / "quick-6pos.yaml"), "--config",
                 str(REPO / "configs" / "sim-lossy.yaml"), "--faults", "rate=0.03", "--dry-run", "-o", str(campaign), "-q", "--no-pdf",
                 "--registry", normalised(str(tmp_path / "registry.sqlite"))]) == 0
    retries = [e for e in load_campaign(campaign).events if e.kind == "retry"]
    assert retries, "the faults made no retry: nothing to group"
    client = TestClient(base_url="http://127.0.0.1", app=create_app([tmp_path], None))
    groups = [g for g in client.get("/api/campaigns/lossy.h5").json()["warning_groups"] if g["kind"] == "retry"]
    assert sum(g["count"] for g in groups) == len(retries) and len(groups) < len(retries)
    assert all(g["recovered"] is True and g["source"] for g in groups)
    assert len({(g["source"], g["what"]) for g in groups}) == len(groups)
    page = client.get("/campaigns/lossy.h5").text
    assert page.count(">recovered</td>") == len(groups)


def test_the_temperature_plot_draws_the_ramps(lab) -> None:
    """Every ramp's air polls are in the plot's series (the DUTs' value missing there: not polled)."""
    import numpy as np

    from accelcal_rig.store.read import load_campaign
    from accelcal_rig.web.campaigns import CampaignFolders

    folder, _ = lab
    campaign = load_campaign(folder / "quick.h5")
    series = CampaignFolders([folder]).series("quick.h5")
    ramp_polls = sum(len(s.ramp_t_s) for s in campaign.soaks)
    assert ramp_polls > 0 and int(np.isnan(series["dut_c"]).sum()) == ramp_polls
    assert len(series["chamber_c"]) == ramp_polls + sum(len(s.t_s) for s in campaign.soaks) + len(campaign.poses)
    assert series["t_h"] == sorted(series["t_h"])
