"""A lab's rigs in one window, as used: two simulated rigs (two `rig run` processes, each its own rig name)
publish into one PostgreSQL registry; the dashboard, in Debian's chromium, shows both advancing without a
reload; then one rig's process is killed with SIGKILL and its card turns to "not heard from since …" within
a minute, never running. Screenshots are written to $ACCELCAL_SCREENSHOTS (default: the test's folder)."""

from __future__ import annotations

import base64
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import yaml

from accelcal_rig.registry.live import STALE_AFTER_S
from accelcal_rig.web.lab import TICK_S
from tests.conftest import SIM_RIG
from tests.web.test_browser import LIVE_PROCEDURE, RIG, DevTools, _started, _stop, _wait_for

CARD = "document.querySelector('a.card[data-rig=\"{rig}\"]')"


def _rig_files(folder: Path, name: str, poses: int) -> Path:
    config = yaml.safe_load(SIM_RIG.read_text())
    config["name"] = name
    (folder / f"{name}.yaml").write_text(yaml.safe_dump(config))
    procedure = folder / f"{name}-procedure.yaml"
    procedure.write_text(LIVE_PROCEDURE.replace("rig: sim.yaml", f"rig: {name}.yaml").replace("count: 80", f"count: {poses}"))
    return procedure


def _card(browser: DevTools, rig: str) -> tuple[str, str]:
    card = CARD.format(rig=rig)
    found = browser.evaluate(f"{card} ? [{card}.className, {card}.querySelector('.headline').textContent] : null")
    return (str(found[0]), str(found[1])) if isinstance(found, list) else ("", "")


def _screenshot(browser: DevTools, name: str, tmp_path: Path) -> Path:
    folder = Path(os.environ.get("ACCELCAL_SCREENSHOTS") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_bytes(base64.b64decode(browser.call("Page.captureScreenshot", format="png")["data"]))
    return path


def test_two_rigs_advance_in_one_window_and_a_killed_one_turns_stale(browser: DevTools, tmp_path: Path,
                                                                     postgresql_url: str) -> None:
    folder = tmp_path / "campaigns"
    folder.mkdir()
    runs = {"rig-north": _rig_files(folder, "rig-north", 80), "rig-south": _rig_files(folder, "rig-south", 400)}
    here = tmp_path / "here"  # the dashboard's own computer: the rigs' campaign files are on theirs
    here.mkdir()
    server, found = _started([RIG, "serve", "--campaigns", str(here), "--registry", postgresql_url, "--port", "0"],
                             r"dashboard on (http://\S+)")
    base = found.group(1).rstrip("/")
    processes = {name: subprocess.Popen(
        [RIG, "run", str(procedure), "--dry-run", "-o", str(folder / f"{name}.h5"), "-q", "--no-pdf",
         "--registry", postgresql_url, "--faults", "rate=1,kinds=delay,delay_s=0.01"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True) for name, procedure in runs.items()}
    try:
        browser.call("Emulation.setDeviceMetricsOverride", width=1280, height=900, deviceScaleFactor=1, mobile=False)
        browser.call("Page.navigate", url=f"{base}/")
        _wait_for(browser, "document.readyState === 'complete'")
        browser.evaluate("window.loadedOnce = true")  # gone if the page ever reloads
        seen: dict[str, list[int]] = {name: [] for name in runs}
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline and min(len(set(s)) for s in seen.values()) < 3:
            for name in runs:
                status, headline = _card(browser, name)
                poses = re.match(r"running · (\d+)/", headline)
                if "status-running" in status and poses:
                    seen[name].append(int(poses.group(1)))
            time.sleep(0.3)
        for name, values in seen.items():  # both advanced on the page, without a reload
            assert len(set(values)) >= 3 and values == sorted(values), (name, values)
        assert browser.evaluate("window.loadedOnce") is True
        _screenshot(browser, "rigs-running.png", tmp_path)

        south = processes["rig-south"]
        assert south.poll() is None, "rig-south ended before it could be killed"
        os.killpg(south.pid, signal.SIGKILL)
        south.wait(timeout=30)
        killed_at = time.monotonic()
        while "status-silent" not in _card(browser, "rig-south")[0]:
            assert "status-running" in _card(browser, "rig-south")[0]  # running until it is stale, nothing else
            assert time.monotonic() - killed_at < 60, "the killed rig was not shown stale within a minute"
            time.sleep(0.5)
        stale_after = time.monotonic() - killed_at
        assert stale_after >= STALE_AFTER_S - 15  # not before it could have been heard from (heartbeat 10 s)
        assert _card(browser, "rig-south")[1].startswith("not heard from since ")
        _screenshot(browser, "rigs-one-stale.png", tmp_path)

        assert processes["rig-north"].wait(timeout=180) == 0
        _wait_for(browser, f"{CARD.format(rig='rig-north')}.className.includes('status-done')", timeout_s=3 * TICK_S)
        assert _card(browser, "rig-north")[1].startswith("done · ")
        assert browser.evaluate("window.loadedOnce") is True
        _screenshot(browser, "rigs-done-and-stale.png", tmp_path)
    finally:
        for process in processes.values():
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
        _stop(server)
