"""The dashboard in a real headless browser (Debian's chromium, driven over the DevTools protocol): the
page loads with every other address unreachable, shows a running dry-run campaign's pose count advancing
without a reload, and — once the campaign is done and recorded — a serial's history."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
import websocket

from tests.conftest import SIM_RIG

RIG = str(Path(sys.executable).parent / "rig")
#: Slow enough to watch (each reply 10 ms late: about six poses a second), short enough for CI.
LIVE_PROCEDURE = """\
name: live-dashboard
rig: sim.yaml
setpoints_c: [24]
soak: {min_dwell_min: 1, window_min: 1, band_c: 0.5, poll_s: 10, timeout_min: 60}
schedule: {kind: sphere, count: 80}
acquisition: {samples_per_pose: 20, range_g: 2, odr_hz: 125, settle_s: 1}
fit: {mode: reference, polynomial_degree: 0}
"""


class DevTools:
    """One page of the browser, spoken to over its DevTools websocket; events are kept as they come."""

    def __init__(self, url: str) -> None:
        self._socket = websocket.create_connection(url, timeout=30)
        self._next = 0
        self.events: list[dict] = []

    def call(self, method: str, **params: object) -> dict:
        self._next += 1
        self._socket.send(json.dumps({"id": self._next, "method": method, "params": params}))
        while True:
            message = json.loads(self._socket.recv())
            if message.get("id") == self._next:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message.get("result", {})
            self.events.append(message)

    def evaluate(self, expression: str) -> object:
        return self.call("Runtime.evaluate", expression=expression, returnByValue=True)["result"].get("value")

    def close(self) -> None:
        self._socket.close()


def _started(argv: list[str], pattern: str, env: dict[str, str] | None = None,
             timeout_s: float = 30.0) -> tuple[subprocess.Popen, re.Match]:
    """A process, and the first line of its output (stdout and stderr together) that matches `pattern`."""
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    deadline = time.monotonic() + timeout_s
    assert process.stdout is not None
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line and process.poll() is not None:
            break
        found = re.search(pattern, line)
        if found:
            return process, found
    process.kill()
    raise AssertionError(f"{argv[0]} did not print {pattern!r}")


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()


@pytest.fixture
def browser() -> Iterator[DevTools]:
    """Headless chromium that can reach 127.0.0.1 and nothing else (every other name resolves to nothing)."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "the browser test needs Debian's chromium (apt-get install chromium)"
    profile = tempfile.mkdtemp(prefix="accelcal-chromium-")
    argv = [chromium, "--headless=new", "--remote-debugging-port=0", f"--user-data-dir={profile}",
            "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1", "--no-first-run", "--disable-gpu",
            "--disable-extensions", "--disable-background-networking", "about:blank"]
    if os.geteuid() == 0:
        argv.insert(1, "--no-sandbox")  # chromium refuses root otherwise (CI runs as root)
    process, found = _started(argv, r"DevTools listening on (ws://\S+)")
    port = re.search(r":(\d+)/", found.group(1)).group(1)  # type: ignore[union-attr]
    pages = json.loads(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10).read())
    tools = DevTools(next(p for p in pages if p["type"] == "page")["webSocketDebuggerUrl"])
    tools.call("Network.enable")
    tools.call("Page.enable")
    try:
        yield tools
    finally:
        tools.close()
        process.kill()
        process.wait(timeout=10)
        shutil.rmtree(profile, ignore_errors=True)


def test_a_running_campaign_advances_on_the_page_and_a_serial_has_its_history(browser: DevTools,
                                                                              tmp_path: Path) -> None:
    folder = tmp_path / "campaigns"
    folder.mkdir()
    shutil.copy(SIM_RIG, folder / "sim.yaml")
    (folder / "live.yaml").write_text(LIVE_PROCEDURE)
    registry = str(tmp_path / "registry.sqlite")
    env = {**os.environ, "ACCELCAL_REGISTRY": registry, "ACCELCAL_DRY_RUN_REGISTRY": registry}  # the dry run's shown
    server, found = _started([RIG, "serve", "--campaigns", str(folder), "--port", "0"],
                             r"dashboard on (http://\S+)", env)
    base = found.group(1).rstrip("/")
    run = subprocess.Popen([RIG, "run", str(folder / "live.yaml"), "--dry-run", "-o", str(folder / "live.h5"), "-q",
                            "--no-pdf", "--faults", "rate=1,kinds=delay,delay_s=0.01"], env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 30
        while not (folder / "live.h5.journal").exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        browser.call("Page.navigate", url=f"{base}/")
        _wait_for(browser, "document.readyState === 'complete' && !!document.querySelector('tr[data-name=\"live.h5\"]')")
        browser.evaluate("window.loadedOnce = true")  # gone if the page ever reloads
        seen: list[int] = []
        cell = "document.querySelector('tr[data-name=\"live.h5\"] td[data-field=\"poses\"]')"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and run.poll() is None:
            text = browser.evaluate(f"{cell} ? {cell}.textContent : ''")
            if isinstance(text, str) and "/" in text:
                done = int(text.split("/")[0])
                if not seen or done != seen[-1]:
                    seen.append(done)
            time.sleep(0.3)
        assert run.wait(timeout=120) == 0
        assert len(seen) >= 3 and seen == sorted(seen) and seen[-1] > seen[0], seen  # it advanced, live
        assert browser.evaluate("window.loadedOnce") is True  # by the page's own refresh, not a reload
        requested = [e["params"]["request"]["url"] for e in browser.events if e["method"] == "Network.requestWillBeSent"]
        assert requested and all(url.startswith(base) for url in requested), requested  # nothing from elsewhere
        assert not [e for e in browser.events if e["method"] == "Network.loadingFailed"]
        browser.call("Page.navigate", url=f"{base}/registry/serials/ADX355-A001")
        _wait_for(browser, "document.readyState === 'complete' && document.querySelectorAll('#history tbody tr').length > 0")
        rows = browser.evaluate("document.querySelectorAll('#history tbody tr').length")
        valid = browser.evaluate("document.getElementById('valid') ? document.getElementById('valid').textContent : ''")
        assert rows == 1 and isinstance(valid, str) and valid.startswith("valid calibration")
    finally:
        if run.poll() is None:
            run.kill()
        _stop(server)


def _wait_for(browser, condition: str, timeout_s: float = 30.0) -> None:
    """Poll the page until the JavaScript `condition` holds, within a deadline."""
    deadline = time.monotonic() + timeout_s
    while browser.evaluate(condition) is not True:
        assert time.monotonic() < deadline, f"the page never came to: {condition}"
        time.sleep(0.05)
