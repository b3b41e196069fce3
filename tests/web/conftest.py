"""The web tests' fixtures from elsewhere: the browser (test_browser.py) and a PostgreSQL database of their
own (the registry tests' server)."""

import pytest

from tests.registry.conftest import postgresql_server, postgresql_url  # noqa: F401 - fixtures
from tests.web.test_browser import browser  # noqa: F401 - a fixture


@pytest.fixture(autouse=True)
def short_event_streams(monkeypatch: pytest.MonkeyPatch) -> None:
    """An event stream asked for in-process ends within a second (a browser opens it again by itself)."""
    monkeypatch.setattr("accelcal_rig.web.lab.STREAM_S", 1.0)
