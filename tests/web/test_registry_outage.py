"""A registry that accepts connections and never answers (a PostgreSQL server hung, a firewall that swallows
the reply): the first request that needs it gets its 503 within the connection timeout; from then on the
registry is known down and no request tries it — none opens a connection — until a probe is due, when one
request (only one) tries again; pages that need no registry never touch it."""

from __future__ import annotations

import socket
import threading
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from accelcal_rig.web.app import create_app
from accelcal_rig.web.registry_gate import PROBE_S


class SilentServer:
    """Accepts every connection, reads nothing, answers nothing; counts the connections."""

    def __init__(self) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.accepted: list[socket.socket] = []
        self._thread = threading.Thread(target=self._accept, daemon=True)
        self._thread.start()

    def _accept(self) -> None:
        while True:
            try:
                connection, _ = self.listener.accept()
            except OSError:
                return
            self.accepted.append(connection)

    def close(self) -> None:
        self.listener.close()
        for connection in self.accepted:
            connection.close()


@pytest.fixture
def silent() -> SilentServer:
    pytest.importorskip("psycopg")
    server = SilentServer()
    yield server
    server.close()


def test_a_silent_registry_is_known_down_and_probed_once_in_a_while(silent: SilentServer, tmp_path: Path) -> None:
    clock = [0.0]
    url = f"postgresql+psycopg://lab@127.0.0.1:{silent.port}/registry"
    client = TestClient(create_app([tmp_path], url, clock=lambda: clock[0]), base_url="http://127.0.0.1")
    first = client.get("/registry")
    assert first.status_code == 503 and "cannot open" in first.text
    tried = len(silent.accepted)
    assert tried >= 1
    for path in ("/registry", "/api/rigs", "/registry/serials/X", "/registry/calibrations/1", "/fragments/rigs"):
        answer = client.get(path)
        assert answer.status_code in (200, 503)             # the rigs fragment says why inside a 200
        assert "tried again every few seconds" in answer.text
    front = client.get("/")
    assert front.status_code == 200 and "tried again every few seconds" in front.text
    for path in ("/static/dashboard.css", "/api/campaigns", "/login"):
        assert client.get(path).status_code == 200
    assert len(silent.accepted) == tried                     # known down: nothing tried it again
    clock[0] += PROBE_S
    assert client.get("/registry").status_code == 503        # the probe, by this request
    assert len(silent.accepted) > tried
    probed = len(silent.accepted)
    assert client.get("/registry").status_code == 503 and len(silent.accepted) == probed


def test_a_read_only_registry_is_shown_and_says_logins_need_a_writable_one(tmp_path: Path) -> None:
    """On a read-only mount (root: a tmpfs remounted ro) the pages read the registry; a login, which writes,
    is refused in one line saying why."""
    import re
    import subprocess

    from accelcal_rig.registry.approvals import Approvals
    from accelcal_rig.registry.database import Registry

    mount = tmp_path / "mnt"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=8m", "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("needs to mount a tmpfs (root)")
    try:
        url = f"sqlite:///{mount / 'registry.sqlite'}"
        Approvals(Registry.open(url)).add_user("jdoe", "Jane Doe", "approver", "approver's secret")
        subprocess.run(["mount", "-o", "remount,ro", str(mount)], check=True)
        client = TestClient(create_app([tmp_path], url), base_url="http://127.0.0.1")
        assert client.get("/registry").status_code == 200
        login = client.get("/login")
        token = re.search(r'name="csrf" value="([^"]+)"', login.text).group(1)
        refused = client.post("/login", data={"csrf": token, "name": "jdoe", "password": "approver's secret"},
                              headers={"origin": "http://127.0.0.1"})
        assert refused.status_code == 409 and "is read-only here" in refused.text and "need a writable one" in refused.text
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)
