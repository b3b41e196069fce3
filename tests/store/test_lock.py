"""The campaign lock: one writer, named when another process asks, gone with its process."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from accelcal_rig.store import lock
from accelcal_rig.store.lock import CampaignBusy, campaign_lock, holder

HOLD = ("import sys, time; from pathlib import Path; from accelcal_rig.store.lock import acquire; "
        "acquire(Path(sys.argv[1]), 'rig run'); print('held', flush=True); time.sleep(60)")


@pytest.fixture
def held_elsewhere(tmp_path: Path):
    campaign = tmp_path / "c.h5"
    process = subprocess.Popen([sys.executable, "-c", HOLD, str(campaign)], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "held"
    yield campaign, process
    process.kill()
    process.wait()


def test_another_process_is_refused_with_its_holder_named(held_elsewhere, monkeypatch) -> None:
    campaign, process = held_elsewhere
    monkeypatch.setattr(lock, "ACQUIRE_PATIENCE_S", 0.1)
    with pytest.raises(CampaignBusy, match=rf"c.h5: in use by pid {process.pid} on {socket.gethostname()} "
                                           r"\(rig run since .*\); nothing was changed"):
        lock.acquire(campaign, "rig resume")
    assert holder(campaign).startswith(f"pid {process.pid} on {socket.gethostname()} (rig run since ")


def test_the_lock_goes_with_a_killed_process(held_elsewhere) -> None:
    campaign, process = held_elsewhere
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    assert holder(campaign) is None
    with campaign_lock(campaign, "rig resume"):
        assert holder(campaign).startswith("this process")


def test_the_lock_is_reentrant_and_readers_never_create_it(tmp_path: Path) -> None:
    campaign = tmp_path / "c.h5"
    assert holder(campaign) is None and not (tmp_path / "c.h5.lock").exists()
    with campaign_lock(campaign, "rig run"):
        with campaign_lock(campaign, "rig run"):
            pass
        assert lock.holds(campaign)
    assert not lock.holds(campaign) and holder(campaign) is None
