"""Notifications reach a local webhook and a local command on start, soak, fault, safe and finish; a
webhook that hangs or refuses costs the campaign at most its timeout per event, and nothing else."""

from __future__ import annotations

import json
import sys
import threading
import time
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import CampaignAborted
from tests.conftest import TINY_PROCEDURE


class Recorder(BaseHTTPRequestHandler):
    received: list[dict] = []
    delay_s = 0.0

    def do_POST(self) -> None:  # noqa: N802 - http.server's naming
        body = self.rfile.read(int(self.headers["Content-Length"]))
        time.sleep(self.delay_s)
        type(self).received.append(json.loads(body))
        self.send_response(204)
        self.end_headers()

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def webhook() -> Iterator[tuple[str, type[Recorder]]]:
    handler = type("Handler", (Recorder,), {"received": [], "delay_s": 0.0})
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/hook", handler
    server.shutdown()
    server.server_close()


def with_notify(workdir: Path, notify: str) -> None:
    rig = workdir / "sim.yaml"
    rig.write_text(rig.read_text() + f"notify: {notify}\n")


def test_webhook_hears_start_soak_safe_and_finish_in_order(write, workdir: Path, webhook) -> None:
    url, handler = webhook
    with_notify(workdir, f"{{webhook_url: '{url}', timeout_s: 5}}")
    output = workdir / "run.h5"
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), output, dry_run=True, seed=0, overwrite=False,
                 calibration=workdir / "cal.yaml")
    events = [n["event"] for n in handler.received]
    assert events == ["start", "soak", "safe", "finish"]
    start, soak, safe, finish = handler.received
    assert start["campaign"] == str(output) and start["procedure"] == "tiny" and start["poses_total"] == 6
    assert "6 poses to measure, about" in start["message"]
    assert "T30: stable after" in soak["message"] and soak["poses_done"] == 0
    assert "safe state" in safe["message"] and safe["poses_done"] == 6
    assert "calibration →" in finish["message"]
    assert finish["format"] == "accelcal-rig notification" and finish["text"].startswith("[tiny] finish:")


def test_a_fault_is_notified_with_its_reason_then_the_safe_state(write, workdir: Path, webhook) -> None:
    url, handler = webhook
    with_notify(workdir, f"{{webhook_url: '{url}', events: [fault, safe]}}")
    with pytest.raises(CampaignAborted):
        run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE), faults="sensor_wrong_id=ADX355-A003"),
                     workdir / "run.h5", dry_run=True, seed=0, overwrite=False)
    assert [n["event"] for n in handler.received] == ["fault", "safe"]
    assert "ADX355-A003" in handler.received[0]["message"]
    assert "rig in its safe state" in handler.received[1]["message"]


def test_a_local_command_gets_each_event_as_json_on_stdin(write, workdir: Path) -> None:
    sink = workdir / "events.jsonl"
    script = f"import sys; open({str(sink)!r}, 'a').write(sys.stdin.read() + '\\n')"
    with_notify(workdir, json.dumps({"command": [sys.executable, "-c", script]}))
    run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), workdir / "run.h5", dry_run=True, seed=0,
                 overwrite=False)
    received = [json.loads(line) for line in sink.read_text().splitlines()]
    assert [n["event"] for n in received] == ["start", "soak", "safe", "finish"]


def test_a_hanging_webhook_and_a_failing_command_never_hold_up_the_campaign(write, workdir: Path, webhook,
                                                                           caplog) -> None:
    url, handler = webhook
    handler.delay_s = 3.0  # far beyond the timeout: every delivery times out
    with_notify(workdir, json.dumps({"webhook_url": url, "command": [sys.executable, "-c", "raise SystemExit(3)"],
                                     "timeout_s": 0.3}))
    prepared = prepare(write("tiny.yaml", TINY_PROCEDURE))
    started = time.perf_counter()
    result = run_campaign(prepared, workdir / "run.h5", dry_run=True, seed=0, overwrite=False)
    wall_s = time.perf_counter() - started
    assert result.summary.state == "done"
    # Four events × (0.3 s webhook timeout + a failing command) at most, delivered beside the campaign.
    assert wall_s < 15.0
    failures = [r.getMessage() for r in caplog.records if "notification" in r.getMessage() and "failed" in r.getMessage()]
    assert any("by webhook failed" in m and "timed out" in m for m in failures), failures
    assert any("by command failed: exit code 3" in m for m in failures), failures


def test_an_unreachable_webhook_is_logged_not_raised(write, workdir: Path, caplog) -> None:
    with_notify(workdir, "{webhook_url: 'http://127.0.0.1:9/nobody', timeout_s: 1}")
    result = run_campaign(prepare(write("tiny.yaml", TINY_PROCEDURE)), workdir / "run.h5", dry_run=True, seed=0,
                          overwrite=False)
    assert result.summary.state == "done"
    assert any("by webhook failed" in r.getMessage() for r in caplog.records)
